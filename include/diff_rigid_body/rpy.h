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
#include <cstddef>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace diff_rigid_body
{
template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Vector6 = Eigen::Matrix<Scalar, 6, 1>;
template <typename Scalar>
using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
template <typename Scalar>
using Matrix6 = Eigen::Matrix<Scalar, 6, 6>;
template <typename Scalar>
using Matrix36 = Eigen::Matrix<Scalar, 3, 6>;

/// Indices into q = (phi, theta, psi, tx, ty, tz).
enum StateIndex : int
{
  PHI = 0,
  THETA = 1,
  PSI = 2,
  TX = 3,
  TY = 4,
  TZ = 5
};

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

/// Sines and cosines of many angles at once, for the batched kernels.
///
/// The loop body is branch-free double arithmetic over a block of
/// kSinCosLanes values, so the compiler vectorises it at the baseline ISA
/// (SSE2: 2 lanes; 4 or 8 under -mavx2 / -mavx512f) with no library call:
///   n = nearest integer to x 2/pi   (the 1.5 2^52 rounding trick),
///   r = x - n pi/2                  (Cody-Waite, pi/2 in three 33-bit parts:
///                                    n p1 and n p2 are exact for |n| < 2^20
///                                    and x - n p1 is exact by Sterbenz),
///   sin r, cos r on [-pi/4, pi/4]   (the fdlibm/glibc minimax polynomials),
///   quadrant n mod 4                (selects and signs, no integers).
/// The absolute error of r is below 1.2e-16, so sin x and cos x are within
/// about 2 ulp of 1 (absolute) of the exact values. A block holding any
/// |x| >= kSinCosFastLimit (1.6e6 rad) or a non-finite value is done with
/// std::sin / std::cos instead, so every input gets a correct answer.
constexpr int kSinCosLanes = 8;
constexpr double kSinCosFastLimit = 1.6e6;  // < 2^20 pi/2

namespace detail
{
/// N angles, all with |x| < kSinCosFastLimit.
template <int N>
inline void sinCosLanes(const double* x, double* s, double* c)
{
  constexpr double two_over_pi = 6.36619772367581382433e-01;
  constexpr double p1 = 1.57079632673412561417e+00;  // first 33 bits of pi/2
  constexpr double p2 = 6.07710050630396597660e-11;  // next 33 bits
  constexpr double p3 = 2.02226624871116645580e-21;  // next 33 bits
  constexpr double round_magic = 6755399441055744.0;  // 1.5 2^52: (y + m) - m rounds y to an integer
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  for (int i = 0; i < N; ++i)
  {
    const double xi = x[i];
    const double n = (xi * two_over_pi + round_magic) - round_magic;
    double r = xi - n * p1;
    r = r - n * p2;
    r = r - n * p3;
    const double z = r * r;
    const double sr = r + (r * z) * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    const double hz = 0.5 * z;
    const double w = 1.0 - hz;
    const double cr = w + (((1.0 - w) - hz) + (z * z) * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6))))));
    // q = n mod 4 in {0, 1, 2, 3}, exactly: floor(n / 4) = round(n / 4 - 3/8) has no ties.
    const double q = n - 4.0 * (((n * 0.25 - 0.375) + round_magic) - round_magic);
    const bool odd = (q == 1.0) | (q == 3.0);
    const double sin_abs = odd ? cr : sr;
    const double cos_abs = odd ? sr : cr;
    s[i] = q >= 2.0 ? -sin_abs : sin_abs;
    c[i] = ((q == 1.0) | (q == 2.0)) ? -cos_abs : cos_abs;
  }
}

/// One block of kSinCosLanes angles, all with |x| < kSinCosFastLimit.
inline void sinCosBlock(const double* x, double* s, double* c)
{
  sinCosLanes<kSinCosLanes>(x, s, c);
}

/// true when all N values may take the fast path.
template <int N = kSinCosLanes>
inline bool sinCosBlockIsFast(const double* x)
{
  bool fast = true;
  for (int i = 0; i < N; ++i)
    fast &= std::abs(x[i]) < kSinCosFastLimit;  // false for NaN as well
  return fast;
}

/// sin and cos of two angles (one SSE2 register): the single-state kernels.
inline void sinCos2(const double* x, double* s, double* c)
{
  if (sinCosBlockIsFast<2>(x))
  {
    sinCosLanes<2>(x, s, c);
  }
  else
  {
    for (int k = 0; k < 2; ++k)
    {
      s[k] = std::sin(x[k]);
      c[k] = std::cos(x[k]);
    }
  }
}
}  // namespace detail

/// s[i] = sin(x[i]), c[i] = cos(x[i]) for i < count (see kSinCosLanes above
/// for the method and its accuracy). The arrays may not overlap.
inline void sinCos(const double* x, std::size_t count, double* s, double* c)
{
  std::size_t i = 0;
  for (; i + kSinCosLanes <= count; i += kSinCosLanes)
  {
    if (detail::sinCosBlockIsFast(x + i))
    {
      detail::sinCosBlock(x + i, s + i, c + i);
    }
    else
    {
      for (int k = 0; k < kSinCosLanes; ++k)
      {
        s[i + k] = std::sin(x[i + k]);
        c[i + k] = std::cos(x[i + k]);
      }
    }
  }
  if (i < count)  // the last count - i < kSinCosLanes values, padded with 0
  {
    const std::size_t rest = count - i;
    double xs[kSinCosLanes] = {}, ss[kSinCosLanes], cs[kSinCosLanes];
    for (int k = 0; k < kSinCosLanes; ++k)
      if (static_cast<std::size_t>(k) < rest)
        xs[k] = x[i + static_cast<std::size_t>(k)];
    if (detail::sinCosBlockIsFast(xs))
    {
      detail::sinCosBlock(xs, ss, cs);
    }
    else
    {
      for (int k = 0; k < kSinCosLanes; ++k)
      {
        ss[k] = std::sin(xs[k]);
        cs[k] = std::cos(xs[k]);
      }
    }
    for (int k = 0; k < kSinCosLanes; ++k)
      if (static_cast<std::size_t>(k) < rest)
      {
        s[i + static_cast<std::size_t>(k)] = ss[k];
        c[i + static_cast<std::size_t>(k)] = cs[k];
      }
  }
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
