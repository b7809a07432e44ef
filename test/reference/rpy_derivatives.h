// dR/dr of the RPY rotation (rpy.h), for tests of the kernels that use the
// equivalent form dR/dr_k = [T_k]_x R without forming dR.
#pragma once

#include <array>

#include "diff_rigid_body/multibody/rpy.h"

namespace diff_rigid_body
{
/// dR/dphi, dR/dtheta, dR/dpsi, by the product rule on the elementary rotations:
///   dR/dphi = Rz Ry Rx',  dR/dtheta = Rz Ry' Rx,  dR/dpsi = Rz' Ry Rx.
/// Equivalently dR/dr_k = [T_k]_x R, with T_k the k-th column of T.
template <typename Scalar>
std::array<Matrix3<Scalar>, 3> rpyToMatrixDerivatives(const RpyTrig<Scalar>& t)
{
  const Matrix3<Scalar> R = rpyToMatrix(t);
  const Matrix3<Scalar> T = angularVelocityMatrixWorld(t);
  std::array<Matrix3<Scalar>, 3> dR;
  for (int k = 0; k < 3; ++k)
  {
    const Vector3<Scalar> axis = T.col(k);
    for (int c = 0; c < 3; ++c)
      dR[k].col(c) = axis.cross(R.col(c));
  }
  return dR;
}

}  // namespace diff_rigid_body
