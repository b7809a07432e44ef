// The Euler-angle chart of a free root: how the rates of its coordinates
// x_r = (phi, theta, psi) map to its angular velocity, the motion
// coordinate the algorithms run in (docs/derivation.md, "Motion
// coordinates"). Templated on the scalar (double; std::complex for the
// complex step; mpfr::mpreal for references).
//
//   w = T(x_r) x_r'          (world axes [rad/s])
//   w' = T x_r'' + Q,        Q = T' x_r' = theta' phi' a + psi' phi' b + psi' theta' c,
// with (c_ = cos, s_ = sin of the angle named)
//   T    = [[c_th c_ps, -s_ps, 0], [c_th s_ps, c_ps, 0], [-s_th, 0, 1]],
//   T^-1 = [[c_ps / c_th, s_ps / c_th, 0], [-s_ps, c_ps, 0], [s_th c_ps / c_th, s_th s_ps / c_th, 1]],
//   a = dT/dtheta e_0 = (-s_th c_ps, -s_th s_ps, -c_th),
//   b = dT/dpsi e_0   = (-c_th s_ps, c_th c_ps, 0),
//   c = dT/dpsi e_1   = (-c_ps, -s_ps, 0)
// (every other column of dT/dtheta, dT/dpsi is 0; T does not depend on
// phi). det T = cos(theta): only T^-1 carries 1 / cos(theta), so the chart
// is singular at gimbal lock and nowhere else.
//
// A body's motion coordinates nu = A x' with A = blockdiag(T, I3, I) for a
// free root (its COM velocity and the joint rates pass unchanged), and the
// identity for a fixed base.
#pragma once

#include <cfloat>

#include "diff_rigid_body/multibody/rpy.h"

namespace diff_rigid_body
{
/// |cos(theta)| below this refuses forward dynamics (the chart's T^-1 is
/// not defined to rounding): 4 DBL_EPSILON, 8.9e-16. The doubles nearest
/// pi/2 have |cos(theta)| of 6.1e-17, 1.6e-16, 3.8e-16 and 6.1e-16.
constexpr double kGimbalLockCosine = 4 * DBL_EPSILON;

template <typename Scalar>
struct FreeRootChart
{
  Scalar s_theta, c_theta, s_psi, c_psi;
  Matrix3<Scalar> T;

  FreeRootChart() = default;
  explicit FreeRootChart(const RpyTrig<Scalar>& trig)
    : s_theta(trig.s_theta), c_theta(trig.c_theta), s_psi(trig.s_psi), c_psi(trig.c_psi)
    , T(angularVelocityMatrixWorld(trig))
  {
  }

  /// T^-1 (see the header comment); defined where cos(theta) != 0.
  Matrix3<Scalar> inverse() const
  {
    const Scalar u = c_psi / c_theta, v = s_psi / c_theta;
    Matrix3<Scalar> out;
    out << u, v, Scalar(0),  //
        -s_psi, c_psi, Scalar(0),  //
        s_theta * u, s_theta * v, Scalar(1);
    return out;
  }

  /// dT/dx_c for c = PHI (0), THETA (1), PSI (2).
  Matrix3<Scalar> derivative(int c) const
  {
    Matrix3<Scalar> out = Matrix3<Scalar>::Zero();
    if (c == THETA)
      out.col(0) = columnA();
    else if (c == PSI)
    {
      out.col(0) = columnB();
      out.col(1) = columnC();
    }
    return out;
  }

  /// Q = T' x_r' for rates r = x_r'.
  Vector3<Scalar> velocityProduct(const Scalar* r) const
  {
    return (r[1] * r[0]) * columnA() + (r[2] * r[0]) * columnB() + (r[2] * r[1]) * columnC();
  }

  /// dQ/dx_r' (3 x 3).
  Matrix3<Scalar> velocityProductByRates(const Scalar* r) const
  {
    const Vector3<Scalar> a = columnA(), b = columnB(), c = columnC();
    Matrix3<Scalar> out;
    out.col(0) = r[1] * a + r[2] * b;
    out.col(1) = r[0] * a + r[2] * c;
    out.col(2) = r[0] * b + r[1] * c;
    return out;
  }

  /// dQ/dx_r (3 x 3; column PHI is 0) at rates r.
  Matrix3<Scalar> velocityProductByAngles(const Scalar* r) const
  {
    const Scalar tp = r[1] * r[0], sp = r[2] * r[0], st = r[2] * r[1];
    Matrix3<Scalar> out;
    out.col(0).setZero();
    out.col(1) << -tp * c_theta * c_psi + sp * s_theta * s_psi, -tp * c_theta * s_psi - sp * s_theta * c_psi,
        tp * s_theta;
    out.col(2) << tp * s_theta * s_psi - sp * c_theta * c_psi + st * s_psi,
        -tp * s_theta * c_psi - sp * c_theta * s_psi - st * c_psi, Scalar(0);
    return out;
  }

private:
  Vector3<Scalar> columnA() const { return Vector3<Scalar>(-s_theta * c_psi, -s_theta * s_psi, -c_theta); }
  Vector3<Scalar> columnB() const { return Vector3<Scalar>(-c_theta * s_psi, c_theta * c_psi, Scalar(0)); }
  Vector3<Scalar> columnC() const { return Vector3<Scalar>(-c_psi, -s_psi, Scalar(0)); }
};

}  // namespace diff_rigid_body
