// The vector-Jacobian product of a body's vertex positions (body_model.h):
// dL/dx = sum_v J_v^T g_v for gradients g_v = dL/dp_v, without forming J.
//
// With J_v = V_c + W_c x (p_v - r) per column (vertex_jacobians.h), per
// segment s the sums
//   G_s = sum g_v,   H_s = sum (p_v - r) x g_v
// over its vertices, accumulated over each subtree (children first), give
//   dL/dx_c = sum over the dofs k that x_c drives of m_k (S_k.v . G + S_k.w . H)
// with G, H those of the subtree k moves. One pass over the vertices: with
// p_v - r = R_s p0 + (p_s - r) and A = (sum g p0^T) R_s^T = sum g (R_s p0)^T,
//   sum (R_s p0) x g = (A_zy - A_yz, A_xz - A_zx, A_yx - A_xy),
// and sum g p0^T comes from the summation engine of every backprop
// (detail/backprop_sums.h) over the segment's vertices stored by coordinate.
// A free object takes the closed form of free_body/vertex_columns.h
// (dL/dr = T^T sum (R p0) x g, dL/dt = sum g).
#pragma once

#include <cstdint>
#include <vector>

#include "diff_rigid_body/multibody/body_workspace.h"

namespace diff_rigid_body
{
/// dL/dx at x (d values into `gradient`) for `gradients` (3 per vertex of
/// `vertices`, empty = all, in order; indices already checked). Returns
/// false, with no answer, where the kinematics at x overflow (a prismatic
/// joint at 1e308); the closed form of a free segment cannot. Nothing is
/// allocated.
bool vertexBackprop(const BodyModel& model, BodyWorkspace<double>& ws, const std::vector<std::uint32_t>& vertices,
                    const double* gradients, const double* x, double* gradient);

}  // namespace diff_rigid_body
