// Generalized mass matrix of one free rigid body in Euler-angle coordinates.
//
//   q = (phi, theta, psi, tx, ty, tz), t = world position of the COM [m]
//   M(q) = blockdiag(T^T I' T, m I3)           (kinetic energy E = 1/2 qdot^T M qdot)
//        = blockdiag(A^T I_b A, m I3)          (I' = R I_b R^T, A = R^T T)
//
// I_b is the inertia about the COM in body axes [kg m^2], m the mass [kg].
// The angular block depends on phi and theta only (yaw about world Z is a
// symmetry), so dM/dpsi = dM/dt = 0. At theta = +-pi/2 (gimbal lock)
// det(A^T I_b A) = cos^2(theta) det(I_b): M has rank 5 but stays finite.
// M is never inverted here.
#pragma once

#include <array>

#include "diff_rigid_body/rpy.h"

namespace diff_rigid_body
{
/// M(q) for a body of mass `mass` [kg] and inertia `inertia_body` [kg m^2]
/// (about the COM, body axes). Only phi = q[0] and theta = q[1] are read.
template <typename Scalar>
Matrix6<Scalar> massMatrix(const RpyTrig<Scalar>& trig, const Scalar& mass, const Matrix3<Scalar>& inertia_body)
{
  const Matrix3<Scalar> A = angularVelocityMatrixBody(trig);
  const Matrix3<Scalar> IA = inertia_body * A;
  Matrix6<Scalar> M = Matrix6<Scalar>::Zero();
  M.template topLeftCorner<3, 3>().noalias() = A.transpose() * IA;
  M(3, 3) = mass;
  M(4, 4) = mass;
  M(5, 5) = mass;
  return M;
}

template <typename Scalar, typename Derived>
Matrix6<Scalar> massMatrix(const Eigen::MatrixBase<Derived>& q, const Scalar& mass,
                           const Matrix3<Scalar>& inertia_body)
{
  return massMatrix(RpyTrig<Scalar>(q[PHI], q[THETA], Scalar(0)), mass, inertia_body);
}

/// dM/dq_j for j = 0..5:
///   d(A^T I_b A)/dr_j = dA_j^T I_b A + A^T I_b dA_j, for j = phi, theta;
///   dM/dpsi = dM/dt = 0.
template <typename Scalar>
std::array<Matrix6<Scalar>, 6> massMatrixDerivatives(const RpyTrig<Scalar>& trig, const Matrix3<Scalar>& inertia_body)
{
  const Matrix3<Scalar> A = angularVelocityMatrixBody(trig);
  const std::array<Matrix3<Scalar>, 2> dA = angularVelocityMatrixBodyDerivatives(trig);
  const Matrix3<Scalar> IA = inertia_body * A;
  std::array<Matrix6<Scalar>, 6> dM;
  for (auto& m : dM)
    m.setZero();
  for (int j = 0; j < 2; ++j)
  {
    // dA^T I A + A^T I dA = X + X^T with X = A^T I dA (I symmetric).
    const Matrix3<Scalar> X = IA.transpose() * dA[j];
    dM[j].template topLeftCorner<3, 3>() = X + X.transpose();
  }
  return dM;
}

template <typename Scalar, typename Derived>
std::array<Matrix6<Scalar>, 6> massMatrixDerivatives(const Eigen::MatrixBase<Derived>& q,
                                                     const Matrix3<Scalar>& inertia_body)
{
  return massMatrixDerivatives(RpyTrig<Scalar>(q[PHI], q[THETA], Scalar(0)), inertia_body);
}

/// cos(theta): the gimbal-lock diagnostic. 1 far from the singularity, 0 at
/// theta = +-pi/2, where the angular block of M loses rank.
template <typename Scalar>
Scalar gimbalLockCosine(const Scalar& theta)
{
  using std::cos;
  return cos(theta);
}

}  // namespace diff_rigid_body
