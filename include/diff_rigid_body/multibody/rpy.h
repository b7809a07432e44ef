// Euler-angle (roll-pitch-yaw) kinematics, templated on the scalar type.
//
// Convention (URDF rpy, tf2::Matrix3x3::setRPY):
//   r = (phi, theta, psi)            [rad]
//   R(r) = Rz(psi) * Ry(theta) * Rx(phi)
// i.e. intrinsic rotations Z, then Y', then X''.
//
// The kernels work for double, float, std::complex<double> (complex-step
// derivatives) and mpfr::mpreal (high-precision reference). Math functions
// are called unqualified so that argument-dependent lookup picks the
// scalar's own sin/cos.
#pragma once

#include <array>
#include <cmath>
#include <complex>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
/// Sines and cosines of the three RPY angles, computed once per state so that
/// every kernel below can share them (trigonometry once per body, never per
/// vertex).
template <typename Scalar>
struct RpyTrig
{
  Scalar s_phi, c_phi, s_theta, c_theta, s_psi, c_psi;

  RpyTrig(const Scalar& phi, const Scalar& theta, const Scalar& psi)
  {
    using std::cos;
    using std::sin;
    s_phi = sin(phi);
    c_phi = cos(phi);
    s_theta = sin(theta);
    c_theta = cos(theta);
    s_psi = sin(psi);
    c_psi = cos(psi);
  }

  template <typename Derived>
  explicit RpyTrig(const Eigen::MatrixBase<Derived>& q) : RpyTrig(q[PHI], q[THETA], q[PSI])
  {
  }

  /// From sines and cosines computed elsewhere (e.g. in one vectorised call),
  /// each array in the order (phi, theta, psi).
  RpyTrig(const Scalar* sines, const Scalar* cosines)
    : s_phi(sines[0])
    , c_phi(cosines[0])
    , s_theta(sines[1])
    , c_theta(cosines[1])
    , s_psi(sines[2])
    , c_psi(cosines[2])
  {
  }
};

/// R = Rz(psi) Ry(theta) Rx(phi), the rotation from the body axes to the fixed frame.
template <typename Scalar>
Matrix3<Scalar> rpyToMatrix(const RpyTrig<Scalar>& t)
{
  Matrix3<Scalar> R;
  R(0, 0) = t.c_theta * t.c_psi;
  R(0, 1) = -t.c_phi * t.s_psi + t.s_phi * t.s_theta * t.c_psi;
  R(0, 2) = t.s_phi * t.s_psi + t.c_phi * t.s_theta * t.c_psi;
  R(1, 0) = t.c_theta * t.s_psi;
  R(1, 1) = t.c_phi * t.c_psi + t.s_phi * t.s_theta * t.s_psi;
  R(1, 2) = -t.s_phi * t.c_psi + t.c_phi * t.s_theta * t.s_psi;
  R(2, 0) = -t.s_theta;
  R(2, 1) = t.s_phi * t.c_theta;
  R(2, 2) = t.c_phi * t.c_theta;
  return R;
}

template <typename Scalar>
Matrix3<Scalar> rpyToMatrix(const Scalar& phi, const Scalar& theta, const Scalar& psi)
{
  return rpyToMatrix(RpyTrig<Scalar>(phi, theta, psi));
}

/// T(r): maps Euler-angle rates to the angular velocity in the fixed frame,
/// omega = T(r) * rdot. Its columns are the world directions of the X'', Y'
/// and Z rotation axes:
///   T = [[cos th cos psi, -sin psi, 0],
///        [cos th sin psi,  cos psi, 0],
///        [-sin th,         0,       1]]
template <typename Scalar>
Matrix3<Scalar> angularVelocityMatrixWorld(const RpyTrig<Scalar>& t)
{
  Matrix3<Scalar> T;
  T << t.c_theta * t.c_psi, -t.s_psi, Scalar(0),  //
      t.c_theta * t.s_psi, t.c_psi, Scalar(0),    //
      -t.s_theta, Scalar(0), Scalar(1);
  return T;
}

/// A(phi, theta) = R^T T: maps Euler-angle rates to the angular velocity in
/// body axes, omega_b = A * rdot. Independent of psi.
///   A = [[1,  0,        -sin th        ],
///        [0,  cos phi,   sin phi cos th],
///        [0, -sin phi,   cos phi cos th]]
template <typename Scalar>
Matrix3<Scalar> angularVelocityMatrixBody(const RpyTrig<Scalar>& t)
{
  Matrix3<Scalar> A;
  A << Scalar(1), Scalar(0), -t.s_theta,            //
      Scalar(0), t.c_phi, t.s_phi * t.c_theta,      //
      Scalar(0), -t.s_phi, t.c_phi * t.c_theta;
  return A;
}

/// dA/dphi and dA/dtheta (dA/dpsi = 0).
template <typename Scalar>
std::array<Matrix3<Scalar>, 2> angularVelocityMatrixBodyDerivatives(const RpyTrig<Scalar>& t)
{
  std::array<Matrix3<Scalar>, 2> dA;
  dA[0] << Scalar(0), Scalar(0), Scalar(0),           //
      Scalar(0), -t.s_phi, t.c_phi * t.c_theta,       //
      Scalar(0), -t.c_phi, -t.s_phi * t.c_theta;
  dA[1] << Scalar(0), Scalar(0), -t.c_theta,          //
      Scalar(0), Scalar(0), -t.s_phi * t.s_theta,     //
      Scalar(0), Scalar(0), -t.c_phi * t.s_theta;
  return dA;
}

/// Inverse of rpyToMatrix for a proper rotation: (phi, theta, psi) with
/// theta in [-pi/2, pi/2] and phi, psi in (-pi, pi]. At gimbal lock
/// (cos theta = 0) only phi -+ psi is determined; psi = 0 is chosen.
inline Vector3<double> matrixToRpy(const Matrix3<double>& R)
{
  const double cos_theta = std::hypot(R(0, 0), R(1, 0));
  const double theta = std::atan2(-R(2, 0), cos_theta);
  const double psi = cos_theta > 1e-12 ? std::atan2(R(1, 0), R(0, 0)) : 0.0;
  // phi from Rz(psi)^T R = Ry(theta) Rx(phi), whose middle row is
  // (0, cos phi, -sin phi). Taking phi consistent with the psi actually chosen
  // keeps R -> rpy -> R accurate to rounding near the lock; atan2(R21, R22)
  // alone would lose eps / cos(theta) (1e-3 at cos theta = 1e-12).
  const double s_psi = std::sin(psi), c_psi = std::cos(psi);
  const double phi = std::atan2(s_psi * R(0, 2) - c_psi * R(1, 2), c_psi * R(1, 1) - s_psi * R(0, 1));
  return { phi, theta, psi };
}

}  // namespace diff_rigid_body

// sinCos, the vectorised sine and cosine of many angles (batched kernels).
#include "diff_rigid_body/algorithm/detail/sin_cos.h"
