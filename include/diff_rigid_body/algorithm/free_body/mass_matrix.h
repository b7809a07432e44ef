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
#include <cstddef>
#include <type_traits>

#include "diff_rigid_body/multibody/rpy.h"

namespace diff_rigid_body
{
/// M from the sines and cosines of phi and theta, written as its 36 values
/// (row-major; M is symmetric, so column-major too). The same M as
/// massMatrix: with the columns of A
///   a0 = e_x,  a1 = (0, c_phi, -s_phi),  a2 = (-s_th, s_phi c_th, c_phi c_th),
/// M_jk = a_j . (I_b a_k), formed from u = I_b a1 and w = I_b a2 (I_b symmetric).
template <typename Scalar>
inline void writeMassMatrix(const Scalar& s_phi, const Scalar& c_phi, const Scalar& s_theta, const Scalar& c_theta,
                            const Scalar& mass, const Matrix3<Scalar>& inertia_body, Scalar* out)
{
  const Matrix3<Scalar>& I = inertia_body;
  const Scalar a21 = s_phi * c_theta, a22 = c_phi * c_theta;
  // u = I a1, w = I a2
  const Scalar u0 = c_phi * I(0, 1) - s_phi * I(0, 2);
  const Scalar u1 = c_phi * I(1, 1) - s_phi * I(1, 2);
  const Scalar u2 = c_phi * I(2, 1) - s_phi * I(2, 2);
  const Scalar w0 = -s_theta * I(0, 0) + a21 * I(0, 1) + a22 * I(0, 2);
  const Scalar w1 = -s_theta * I(1, 0) + a21 * I(1, 1) + a22 * I(1, 2);
  const Scalar w2 = -s_theta * I(2, 0) + a21 * I(2, 1) + a22 * I(2, 2);
  const Scalar m00 = I(0, 0);
  const Scalar m01 = u0;
  const Scalar m02 = w0;
  const Scalar m11 = c_phi * u1 - s_phi * u2;
  const Scalar m12 = c_phi * w1 - s_phi * w2;
  const Scalar m22 = -s_theta * w0 + a21 * w1 + a22 * w2;
  const Scalar zero(0);
  // Row by row; rows 3..5 are (0 0 0 | m I3).
  out[0] = m00, out[1] = m01, out[2] = m02, out[3] = zero, out[4] = zero, out[5] = zero;
  out[6] = m01, out[7] = m11, out[8] = m12, out[9] = zero, out[10] = zero, out[11] = zero;
  out[12] = m02, out[13] = m12, out[14] = m22, out[15] = zero, out[16] = zero, out[17] = zero;
  out[18] = zero, out[19] = zero, out[20] = zero, out[21] = mass, out[22] = zero, out[23] = zero;
  out[24] = zero, out[25] = zero, out[26] = zero, out[27] = zero, out[28] = mass, out[29] = zero;
  out[30] = zero, out[31] = zero, out[32] = zero, out[33] = zero, out[34] = zero, out[35] = mass;
}

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

/// In double, the sines and cosines of phi and theta come from the
/// vectorised sinCos of rpy.h (both angles in one SSE2 register, within
/// ~2 ulp of 1 like std::sin / cos) and M is written entry by entry
/// (writeMassMatrix): the same M as the RpyTrig overload to a few ulp, in a
/// fraction of the time (docs/benchmarks.md).
template <typename Scalar, typename Derived>
Matrix6<Scalar> massMatrix(const Eigen::MatrixBase<Derived>& q, const Scalar& mass,
                           const Matrix3<Scalar>& inertia_body)
{
  if constexpr (std::is_same<Scalar, double>::value)
  {
    const double angles[2] = { q[PHI], q[THETA] };
    double s[2], c[2];
    detail::sinCos2(angles, s, c);
    Matrix6<double> M;
    writeMassMatrix(s[0], c[0], s[1], c[1], mass, inertia_body, M.data());
    return M;
  }
  else
  {
    return massMatrix(RpyTrig<Scalar>(q[PHI], q[THETA], Scalar(0)), mass, inertia_body);
  }
}

/// Batched M: for k < count, the state q_k = q + k * stride (only phi =
/// q_k[0] and theta = q_k[1] are read) gives M(q_k), written as 36 values
/// (row-major) at mass_matrices + 36 k, and cos(theta_k) at cos_theta[k]
/// when cos_theta is not null. One body (mass, inertia_body) for all states.
///
/// In double the trigonometry of a whole block of states is done at once
/// by the vectorised sinCos (rpy.h); other scalars call std::sin / cos per
/// state. The result equals massMatrix(q_k, ...) to a few ulp.
template <typename Scalar>
void massMatrixBatch(const Scalar* q, std::size_t count, std::size_t stride, const Scalar& mass,
                     const Matrix3<Scalar>& inertia_body, Scalar* mass_matrices, Scalar* cos_theta = nullptr)
{
  std::size_t k = 0;
  if constexpr (std::is_same<Scalar, double>::value)
  {
    constexpr std::size_t L = kSinCosLanes;
    double angles[2 * L], sines[2 * L], cosines[2 * L];
    for (; k + L <= count; k += L)
    {
      for (std::size_t l = 0; l < L; ++l)
      {
        angles[l] = q[(k + l) * stride + PHI];
        angles[L + l] = q[(k + l) * stride + THETA];
      }
      sinCos(angles, 2 * L, sines, cosines);
      for (std::size_t l = 0; l < L; ++l)
        writeMassMatrix(sines[l], cosines[l], sines[L + l], cosines[L + l], mass, inertia_body,
                        mass_matrices + 36 * (k + l));
      if (cos_theta)
        for (std::size_t l = 0; l < L; ++l)
          cos_theta[k + l] = cosines[L + l];
    }
  }
  for (; k < count; ++k)  // the tail, and every state for other scalars
  {
    using std::cos;
    using std::sin;
    const Scalar& phi = q[k * stride + PHI];
    const Scalar& theta = q[k * stride + THETA];
    const Scalar c_theta = cos(theta);
    writeMassMatrix(Scalar(sin(phi)), Scalar(cos(phi)), Scalar(sin(theta)), c_theta, mass, inertia_body,
                    mass_matrices + 36 * k);
    if (cos_theta)
      cos_theta[k] = c_theta;
  }
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

}  // namespace diff_rigid_body
