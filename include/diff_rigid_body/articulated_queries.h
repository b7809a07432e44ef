// Vertex Jacobians, backprop and dM/dx of an articulated body in double
// precision, on top of articulated_kinematics.h (same conventions).
//
//   J_v = dp_v/dx = V_s + W_s x (p_v - r), column by column, for vertex v of
//         segment s; V_s, W_s (3 x dof) sum m_j v_j and m_j w_j over the
//         joints j on the path to s, per coordinate
//   dL/dx = sum_v J_v^T g_v: with G_s = sum g_v and H_s = sum (p_v - r) x g_v
//           over the vertices of segment s's subtree, coordinate c gets
//           sum m_j (v_j . G_s + w_j . H_s) over the joints j (of segments s)
//           that it drives, and a floating root's Euler angle k gets
//           T_k . H_root and its translation G_root;
// so backprop costs one pass over the vertices plus O(segments).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/articulated_kinematics.h"

namespace diff_rigid_body
{
/// dM/dx_j for j = 0..dof-1, exact to rounding (forward-mode automatic
/// differentiation of articulatedMassMatrix, one direction per coordinate).
std::vector<Eigen::MatrixXd> articulatedMassMatrixDerivatives(const ArticulatedBody& body, const double* x);

/// Positions (3 per vertex, fixed frame) and Jacobians (3 x dof per vertex,
/// row-major) of `vertices` (empty = all, in order), written from
/// `positions` and `jacobians` on. `columns` selects the Jacobian columns
/// written, in x order (empty = all); the compact transport leaves out a
/// floating root's translation columns.
void articulatedVertexJacobians(const ArticulatedBody& body, const ArticulatedPose<double>& pose,
                                const std::vector<std::uint32_t>& vertices, const std::vector<int>& columns,
                                double* positions, double* jacobians);

/// dL/dx (dof values, written to `gradient`) for gradients g (3 per vertex
/// of `vertices`, empty = all).
void articulatedBackprop(const ArticulatedBody& body, const ArticulatedPose<double>& pose,
                         const std::vector<std::uint32_t>& vertices, const double* gradients, double* gradient);

}  // namespace diff_rigid_body
