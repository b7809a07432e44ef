// What every query of one body writes (Pinocchio's Data beside its Model):
// buffers sized once from a BodyModel and reused, so that an algorithm
// allocates nothing per call. One workspace per thread and body; the model
// is shared and never written. Templated on the scalar, as the algorithms.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/multibody/body_model.h"
#include "diff_rigid_body/multibody/free_root_chart.h"
#include "diff_rigid_body/multibody/spatial.h"

namespace diff_rigid_body
{
template <typename Scalar>
struct BodyWorkspace
{
  using MatrixX = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using VectorX = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  explicit BodyWorkspace(const BodyModel& model)
    : segments(model.segments.size()), dofs(model.dofs.size()), coordinates(model.coordinates)
  {
    const std::size_t n = segments, d = coordinates;
    R.resize(n);
    p.resize(n);
    S.resize(dofs);
    joint_angle.resize(n + 3);
    joint_sine.resize(n + 3);
    joint_cosine.resize(n + 3);
    composite.resize(n);
    momentum.resize(dofs);
    M.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    H.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    nu.resize(static_cast<Eigen::Index>(d));
    nu_dot.resize(static_cast<Eigen::Index>(d));
    force_nu.resize(static_cast<Eigen::Index>(d));
    rotation_columns.resize(static_cast<Eigen::Index>(d), 3);
    chart_columns.resize(static_cast<Eigen::Index>(d), 2);
    carried_rate.resize(dofs);
    body_inertia.resize(n);
    dof_velocity.resize(dofs);
    dof_acceleration.resize(dofs);
    subtree_force.resize(n);
    velocity_rate.resize(n);
    composite_velocity_rate.resize(n);
    dof_terms.resize(dofs);
    momentum_rate.resize(dofs);
    factor.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    derivative_x.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    derivative_xd.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    inverse_mass.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    factor_rows.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    inverse_h.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    product.resize(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    solution.resize(static_cast<Eigen::Index>(d));
    segment_sums.resize(n);
    column_motion.assign(6 * d, 0.0);
    segment_selected.assign(n, 0);
    tau.resize(static_cast<Eigen::Index>(d));
  }

  /// True when the workspace was sized for `model`.
  bool fits(const BodyModel& model) const
  {
    return segments == model.segments.size() && dofs == model.dofs.size() && coordinates == model.coordinates;
  }

  std::size_t segments, dofs, coordinates;

  // ---- kinematics.h: forwardKinematics ----
  std::vector<Matrix3<Scalar>> R;  ///< per segment: its frame's axes in the fixed frame
  std::vector<Vector3<Scalar>> p;  ///< per segment: its frame's origin in the fixed frame [m]
  std::vector<Motion<Scalar>> S;   ///< per dof: its unit motion at r, fixed axes
  Vector3<Scalar> r = Vector3<Scalar>::Zero();  ///< the reference point of every spatial quantity [m]
  /// Joint angles and their sines and cosines (the free root's phi, theta,
  /// psi after the joints), so that the double path takes them in one
  /// vectorised call.
  std::vector<Scalar> joint_angle, joint_sine, joint_cosine;
  FreeRootChart<Scalar> chart;  ///< a free root's chart at x (free_root_chart.h)

  // ---- motion_coordinates.h ----
  VectorX nu, nu_dot;  ///< d: motion coordinates and their rates
  VectorX force_nu;    ///< d: a generalized force in nu (A^-T tau)
  MatrixX rotation_columns;  ///< d x 3: H's columns of a free root's w
  MatrixX chart_columns;     ///< d x 2: scratch of the chart's theta and psi columns

  // ---- crba.h ----
  std::vector<Inertia<Scalar>> composite;  ///< per segment: its subtree's inertia about r
  std::vector<Force<Scalar>> momentum;     ///< per dof: composite[its segment] S
  MatrixX H;                               ///< d x d: the mass matrix in nu
  MatrixX M;                               ///< d x d: in x, A^T H A

  // ---- mass_matrix_derivatives.h ----
  std::vector<Inertia<Scalar>> carried_rate;  ///< per dof: the rate of composite[its segment] under its motion

  // ---- rnea.h ----
  std::vector<Inertia<Scalar>> body_inertia;     ///< per segment: its own inertia about r
  std::vector<Motion<Scalar>> dof_velocity;      ///< per dof: the velocity of what it moves [rad/s, m/s]
  std::vector<Motion<Scalar>> dof_acceleration;  ///< per dof: spatial, gravity included [rad/s^2, m/s^2]
  std::vector<Force<Scalar>> subtree_force;      ///< per segment: its subtree's Newton-Euler force [N m, N]
  VectorX tau;                                   ///< d

  // ---- rnea_derivatives.h ----
  using Matrix6 = Eigen::Matrix<Scalar, 6, 6>;
  /// Per segment: how its Newton-Euler force varies with the motion of its
  /// body, B_s (rnea_derivatives.h), then summed over its subtree.
  std::vector<Matrix6> velocity_rate;
  std::vector<Matrix6> composite_velocity_rate;
  struct DofTerms
  {
    Motion<Scalar> u;      ///< S_k x v_l (l: the last dof of k's block; k itself but in a free root's rotations)
    Motion<Scalar> ubar;   ///< u_k - v_carrier x S_k (2 u_k when the carrier is the parent)
    Motion<Scalar> w;      ///< S_k x a_l - u_k x v_l
    Force<Scalar> gamma;   ///< B^c^T S_k
    Force<Scalar> moved;   ///< what moving dof k adds to the subtree force above it (by q or q')
  };
  std::vector<DofTerms> dof_terms;
  std::vector<Force<Scalar>> momentum_rate;  ///< per dof: what its velocity adds to the subtree force above it

  // ---- forward_dynamics.h ----
  MatrixX factor;       ///< d x d: H's factorization (tree_factorization.h)
  MatrixX factor_rows;  ///< d x d: scratch of solveMassMatrixColumns
  MatrixX inverse_h;    ///< d x d: H^-1
  MatrixX product;      ///< d x d: scratch of a product
  VectorX solution;  ///< d
  /// d x d each: d(tau or x'')/dx, d(tau or x'')/dx', M^-1, for the node's answers.
  MatrixX derivative_x, derivative_xd, inverse_mass;

  // ---- vertex_backprop.h ----
  struct SegmentSums
  {
    Matrix3<Scalar> outer = Matrix3<Scalar>::Zero();  ///< sum g p0^T over its vertices
    Vector3<Scalar> force = Vector3<Scalar>::Zero();  ///< sum g, then over its subtree
    Vector3<Scalar> moment = Vector3<Scalar>::Zero();  ///< sum (p - r) x g, then over its subtree
  };
  std::vector<SegmentSums> segment_sums;

  // ---- vertex_jacobians.h ----
  /// One segment's written columns (V_c, W_c): rows V_x, V_y, V_z, W_x, W_y, W_z, width apart.
  std::vector<double> column_motion;
  /// Per segment: whether a requested vertex lies on it.
  std::vector<char> segment_selected;
};

}  // namespace diff_rigid_body
