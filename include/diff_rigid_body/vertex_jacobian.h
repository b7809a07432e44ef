// Vertex positions, vertex Jacobians and their vector-Jacobian product.
//
//   p = R(r) p0 + t                     p0: vertex in the body frame (origin at COM) [m]
//   J = dp/dq = [ -[R p0]_x T | I3 ]    3x6, columns in q order
//
// Column k < 3 of J is T_k x (R p0): the world axis of the k-th Euler
// rotation crossed with the lever arm, so trigonometry is done once per body
// and each vertex costs one 3x3 product and three cross products.
//
// Backprop (vector-Jacobian product), given g_i = dL/dp_i:
//   dL/dr = T^T sum_i (R p0_i) x g_i,   dL/dt = sum_i g_i.
// With W = sum_i g_i p0_i^T (3x3) and X = R W^T = sum_i (R p0_i) g_i^T,
//   sum_i (R p0_i) x g_i = (X12 - X21, X20 - X02, X01 - X10),
// so the per-vertex work is one 3x3 rank-1 update; J is never formed.
#pragma once

#include <cstdint>
#include <vector>

#include "diff_rigid_body/rpy.h"

namespace diff_rigid_body
{
template <typename Scalar>
using Matrix3X = Eigen::Matrix<Scalar, 3, Eigen::Dynamic>;

/// Everything a vertex kernel needs from q, computed once per body.
template <typename Scalar>
struct BodyPose
{
  Matrix3<Scalar> R;  ///< body axes -> fixed frame
  Matrix3<Scalar> T;  ///< Euler rates -> world angular velocity
  Vector3<Scalar> t;  ///< COM in the fixed frame [m]

  template <typename Derived>
  explicit BodyPose(const Eigen::MatrixBase<Derived>& q)
  {
    const RpyTrig<Scalar> trig(q[PHI], q[THETA], q[PSI]);
    R = rpyToMatrix(trig);
    T = angularVelocityMatrixWorld(trig);
    t << q[TX], q[TY], q[TZ];
  }
};

/// p = R p0 + t.
template <typename Scalar>
Vector3<Scalar> vertexPosition(const BodyPose<Scalar>& pose, const Vector3<Scalar>& p0)
{
  return pose.R * p0 + pose.t;
}

/// J = dp/dq (3x6) for one body-frame vertex p0.
template <typename Scalar>
Matrix36<Scalar> vertexJacobian(const BodyPose<Scalar>& pose, const Vector3<Scalar>& p0)
{
  const Vector3<Scalar> lever = pose.R * p0;
  Matrix36<Scalar> J;
  for (int k = 0; k < 3; ++k)
    J.col(k) = pose.T.col(k).cross(lever);
  J.template rightCols<3>().setIdentity();
  return J;
}

/// Positions (3 per vertex) and Jacobians (18 per vertex, 3x6 row-major) for
/// the selected vertices, written to caller-owned buffers.
///
/// \param vertices  body-frame vertices, one per column [m]
/// \param indices   vertices to evaluate; empty means all, in order. Indices
///                  must already be validated (< vertices.cols()).
/// \param positions out, 3 * count values, or nullptr to skip
/// \param jacobians out, 18 * count values, or nullptr to skip
template <typename Scalar>
void vertexPositionsAndJacobians(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                 const std::vector<std::uint32_t>& indices, Scalar* positions, Scalar* jacobians)
{
  const bool all = indices.empty();
  const std::size_t count = all ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  const Matrix3<Scalar>& R = pose.R;
  const Matrix3<Scalar>& T = pose.T;
  for (std::size_t n = 0; n < count; ++n)
  {
    const Eigen::Index v = all ? static_cast<Eigen::Index>(n) : static_cast<Eigen::Index>(indices[n]);
    const Vector3<Scalar> lever = R * vertices.col(v);
    if (positions)
    {
      Scalar* p = positions + 3 * n;
      p[0] = lever[0] + pose.t[0];
      p[1] = lever[1] + pose.t[1];
      p[2] = lever[2] + pose.t[2];
    }
    if (jacobians)
    {
      // Row-major 3x6: row i = (d p_i / d r_0..2, e_i).
      Scalar* J = jacobians + 18 * n;
      for (int k = 0; k < 3; ++k)
      {
        const Vector3<Scalar> column = T.col(k).cross(lever);
        J[k] = column[0];
        J[6 + k] = column[1];
        J[12 + k] = column[2];
      }
      J[3] = Scalar(1), J[4] = Scalar(0), J[5] = Scalar(0);
      J[9] = Scalar(0), J[10] = Scalar(1), J[11] = Scalar(0);
      J[15] = Scalar(0), J[16] = Scalar(0), J[17] = Scalar(1);
    }
  }
}

/// dL/dq = sum_i J_i^T g_i without forming J.
///
/// \param gradients dL/dp for each selected vertex, 3 per vertex, in the
///                  order of `indices` (or of all vertices when empty).
template <typename Scalar>
Vector6<Scalar> backpropagateVertexGradients(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                             const std::vector<std::uint32_t>& indices, const Scalar* gradients)
{
  const bool all = indices.empty();
  const std::size_t count = all ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  Matrix3<Scalar> W = Matrix3<Scalar>::Zero();  // sum_i g_i p0_i^T
  Vector3<Scalar> force = Vector3<Scalar>::Zero();  // sum_i g_i
  for (std::size_t n = 0; n < count; ++n)
  {
    const Eigen::Index v = all ? static_cast<Eigen::Index>(n) : static_cast<Eigen::Index>(indices[n]);
    const Eigen::Map<const Vector3<Scalar>> g(gradients + 3 * n);
    W.noalias() += g * vertices.col(v).transpose();
    force += g;
  }
  const Matrix3<Scalar> X = pose.R * W.transpose();  // sum_i (R p0_i) g_i^T
  const Vector3<Scalar> torque(X(1, 2) - X(2, 1), X(2, 0) - X(0, 2), X(0, 1) - X(1, 0));
  Vector6<Scalar> dL_dq;
  dL_dq.template head<3>() = pose.T.transpose() * torque;
  dL_dq.template tail<3>() = force;
  return dL_dq;
}

}  // namespace diff_rigid_body
