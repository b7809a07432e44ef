// The pose of one body, as every vertex kernel needs it, computed once per
// body from its state q = (phi, theta, psi, tx, ty, tz):
//   p = R(r) p0 + t                     p0: vertex in the body frame (origin at COM) [m]
//   J = dp/dq = [ -[R p0]_x T | I3 ]    3x6, columns in q order
// Column k < 3 of J is T_k x (R p0): the world axis of the k-th Euler
// rotation crossed with the lever arm, so trigonometry is done once per body
// and each vertex costs one 3x3 product and three cross products.
#pragma once

#include <Eigen/Core>

#include "diff_rigid_body/multibody/rpy.h"
#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
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

namespace detail
{
/// R p0 with a fixed order of operations, (R_i0 x + R_i1 y) + R_i2 z per
/// row, shared by every vertex kernel (scalar and SIMD paths), so that all
/// of them return the same bits for the same vertex.
template <typename Scalar, typename Derived>
Vector3<Scalar> rotate(const Matrix3<Scalar>& R, const Eigen::MatrixBase<Derived>& p0)
{
  const Scalar x = p0[0], y = p0[1], z = p0[2];
  return Vector3<Scalar>((R(0, 0) * x + R(0, 1) * y) + R(0, 2) * z,  //
                         (R(1, 0) * x + R(1, 1) * y) + R(1, 2) * z,  //
                         (R(2, 0) * x + R(2, 1) * y) + R(2, 2) * z);
}

/// a x b, component by component as written (the SIMD paths repeat it).
template <typename Scalar, typename DerivedA>
Vector3<Scalar> cross(const Eigen::MatrixBase<DerivedA>& a, const Vector3<Scalar>& b)
{
  return Vector3<Scalar>(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}

/// Outputs of one vertex from its lever arm R p0: the position R p0 + t (3
/// values at P unless P is null) and, unless J is null, the 3 rows of
/// Cols values of the Jacobian, row i = (dp_i/dr_0..2) for Cols = 3, or
/// (dp_i/dr_0..2, e_i) for Cols = 6. Computed in Scalar, stored as Out.
template <int Cols, typename Scalar, typename Out>
void writeVertexOutputs(const BodyPose<Scalar>& pose, const Vector3<Scalar>& lever, Out* P, Out* J)
{
  static_assert(Cols == 3 || Cols == 6, "J rows hold dp/dr (3) or dp/dq (6)");
  if (P)
    for (int i = 0; i < 3; ++i)
      P[i] = static_cast<Out>(lever[i] + pose.t[i]);
  if (!J)
    return;
  for (int k = 0; k < 3; ++k)
  {
    const Vector3<Scalar> column = cross(pose.T.col(k), lever);
    for (int i = 0; i < 3; ++i)
      J[Cols * i + k] = static_cast<Out>(column[i]);
  }
  if constexpr (Cols == 6)
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        J[Cols * i + 3 + k] = static_cast<Out>(i == k ? 1 : 0);
}
}  // namespace detail

}  // namespace diff_rigid_body
