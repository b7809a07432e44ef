// One vertex at a time: p and J = dp/dq of a single body-frame vertex, with
// the order of operations of the batched kernels (vertex_jacobian.h), so
// that they return the same bits. Reference for tests and benchmarks; the
// node runs the batched kernels.
#pragma once

#include "diff_rigid_body/algorithm/free_body/pose.h"
#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
/// p = R p0 + t.
template <typename Scalar>
Vector3<Scalar> vertexPosition(const BodyPose<Scalar>& pose, const Vector3<Scalar>& p0)
{
  return detail::rotate(pose.R, p0) + pose.t;
}

/// J = dp/dq (3x6) for one body-frame vertex p0.
template <typename Scalar>
Matrix36<Scalar> vertexJacobian(const BodyPose<Scalar>& pose, const Vector3<Scalar>& p0)
{
  const Vector3<Scalar> lever = detail::rotate(pose.R, p0);
  Matrix36<Scalar> J;
  for (int k = 0; k < 3; ++k)
    J.col(k) = detail::cross(pose.T.col(k), lever);
  J.template rightCols<3>().setIdentity();
  return J;
}

}  // namespace diff_rigid_body
