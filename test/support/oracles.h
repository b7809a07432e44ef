// Test oracles of the kernels (rpy.h, mass_matrix.h, vertex_jacobian.h)
// beyond the kinematics of kinematics_oracles.h (included): fixed-seed
// random states, bodies and inertias, the hard-case list of
// docs/derivation.md ("Hard cases"), exact angle reduction (MPFR), a
// complex-step helper and error metrics (max-abs, ulp). Needs MPFR (mpreal.h),
// so only test_core includes it.
#pragma once

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <mpreal.h>

#include "kinematics_oracles.h"

namespace drb_test
{
using Complex = std::complex<double>;

constexpr double kEps = std::numeric_limits<double>::epsilon();  // 2^-52
constexpr double kPi = 3.14159265358979323846;
constexpr double kHalfPi = kPi / 2;  // == M_PI_2, the double nearest pi/2

// ---------------------------------------------------------------------------
// Complex step.

/// The complex-step increment. Im(f(x + i h))/h = f'(x) + O(h^2) with no
/// subtractive cancellation, so h can be tiny; 1e-30 makes the O(h^2) term
/// vanish (1e-60 relative) without any underflow for our magnitudes.
constexpr double kComplexStepH = 1e-30;

inline Vector6<Complex> complexPerturbed(const Vector6<double>& q, int j)
{
  Vector6<Complex> qc = q.cast<Complex>();
  qc[j] += Complex(0.0, kComplexStepH);
  return qc;
}

/// d f / d q_j by the complex step; f maps Vector6<Complex> to any complex
/// Eigen matrix or a scalar.
template <typename F>
auto complexStep(const F& f, const Vector6<double>& q, int j)
{
  const auto value = f(complexPerturbed(q, j));
  return Eigen::MatrixXd(value.imag() / kComplexStepH);
}

// ---------------------------------------------------------------------------
// Fixed-seed random inputs.

/// Deterministic generator. Every test constructs its own with a fixed seed.
class Random
{
public:
  explicit Random(std::uint64_t seed) : engine_(seed)
  {
  }

  double uniform(double lo, double hi)
  {
    return std::uniform_real_distribution<double>(lo, hi)(engine_);
  }

  /// log-uniform on [lo, hi], lo > 0.
  double logUniform(double lo, double hi)
  {
    return std::exp(uniform(std::log(lo), std::log(hi)));
  }

  int integer(int lo, int hi)
  {
    return std::uniform_int_distribution<int>(lo, hi)(engine_);
  }

  /// Angles uniform in (-pi, pi] for all three (theta beyond +-pi/2 is a valid
  /// state too), translation in [-10, 10]^3 m.
  Vector6<double> state()
  {
    Vector6<double> q;
    for (int i = 0; i < 3; ++i)
      q[i] = uniform(-kPi, kPi);
    for (int i = 3; i < 6; ++i)
      q[i] = uniform(-10.0, 10.0);
    return q;
  }

  Vector3<double> vector(double scale)
  {
    return Vector3<double>(uniform(-scale, scale), uniform(-scale, scale), uniform(-scale, scale));
  }

  /// A vertex of norm `scale`, random direction.
  Vector3<double> vertexOfNorm(double scale)
  {
    Vector3<double> v;
    do
      v = vector(1.0);
    while (v.norm() < 0.1 || v.norm() > 1.0);
    return v.normalized() * scale;
  }

  Matrix3<double> rotation()
  {
    return refRotation(uniform(-kPi, kPi), uniform(-kPi, kPi), uniform(-kPi, kPi));
  }

  /// A physical inertia tensor (principal moments y+z, x+z, x+y with second
  /// moments x, y, z > 0, so the triangle inequality holds) in random body
  /// axes, scaled by `scale` [kg m^2]. Exactly symmetric.
  Matrix3<double> inertia(double scale = 1.0)
  {
    const double x = uniform(0.05, 1.0), y = uniform(0.05, 1.0), z = uniform(0.05, 1.0);
    const Eigen::Vector3d moments(y + z, x + z, x + y);
    const Matrix3<double> Q = rotation();
    Matrix3<double> I = scale * Q * moments.asDiagonal() * Q.transpose();
    return Matrix3<double>((I + I.transpose()) / 2.0);
  }

  Vector6<double> vector6(double scale)
  {
    Vector6<double> v;
    for (int i = 0; i < 6; ++i)
      v[i] = uniform(-scale, scale);
    return v;
  }

private:
  std::mt19937_64 engine_;
};

// ---------------------------------------------------------------------------
// Hard cases (docs/derivation.md, "Hard cases").

/// Gimbal lock: theta = +-pi/2 (the doubles nearest) and +-pi/2 +- 10^-k,
/// k = 1..16. For k >= 16 the offset is below half an ulp of pi/2 and the sum
/// may round back to +-pi/2: that is part of the case.
inline std::vector<double> gimbalLockThetas()
{
  std::vector<double> thetas = { kHalfPi, -kHalfPi };
  for (int k = 1; k <= 16; ++k)
  {
    const double d = std::pow(10.0, -k);
    for (const double base : { kHalfPi, -kHalfPi })
    {
      thetas.push_back(base + d);
      thetas.push_back(base - d);
    }
  }
  return thetas;
}

/// One rng.state() per gimbalLockThetas() entry, in that order, with theta
/// set to it.
inline std::vector<Vector6<double>> gimbalLockStates(Random& rng)
{
  std::vector<Vector6<double>> states;
  for (const double theta : gimbalLockThetas())
  {
    Vector6<double> q = rng.state();
    q[1] = theta;
    states.push_back(q);
  }
  return states;
}

/// The subset of gimbalLockThetas() at which cos^2(theta) is below double
/// resolution relative to 1, so M is numerically rank 5 (|cos theta| < 1e-8).
inline bool isNumericallyLocked(double theta)
{
  return std::abs(std::cos(theta)) < 1e-8;
}

/// Angles outside (-pi, pi], up to 1e6 rad.
inline std::vector<double> largeAngles()
{
  return { 1e6, -1e6, 999999.123456789, -987654.321, 123456.789, 31415.9265358979, 1e5 + kHalfPi, 4.0 * kPi, -7.5,
           1e3 * kPi, 2.0 * kPi * 159154.0 + 0.25 };
}

/// The angle a reduced to [-pi, pi] exactly (256-bit MPFR, pi to 256 bits),
/// then rounded to double: the only error is that final rounding, at most
/// half an ulp of pi (2.2e-16 rad). Compare with std::remainder(a, 2*M_PI),
/// whose error grows like |a|/(2 pi) * |2 pi - fl(2 pi)| = |a| * 3.9e-17.
inline double wrapAngleExact(double a)
{
  const mp_prec_t prec = 256;
  const mpfr::mpreal x(a, prec);
  const mpfr::mpreal two_pi = 2 * mpfr::const_pi(prec);
  const mpfr::mpreal k = mpfr::round(x / two_pi);
  return (x - k * two_pi).toDouble();
}

/// Vertex scales [m]: bodies as small as 1e-6 m and vertices up to 1e4 m
/// from the COM.
inline std::vector<double> vertexScales()
{
  return { 1e-6, 1e-3, 1.0, 1e2, 1e4 };
}

// ---------------------------------------------------------------------------
// Metrics.

template <typename Derived>
double maxAbs(const Eigen::MatrixBase<Derived>& m)
{
  return m.size() == 0 ? 0.0 : static_cast<double>(m.cwiseAbs().maxCoeff());
}

/// Spacing of doubles at |x| (ulp(1) = 2^-52).
inline double ulp(double x)
{
  x = std::abs(x);
  return std::nextafter(x, std::numeric_limits<double>::infinity()) - x;
}

template <typename Derived>
bool allFinite(const Eigen::MatrixBase<Derived>& m)
{
  return m.allFinite();
}

/// Running maximum, printed at the end of a test so that measured errors are
/// visible in the log next to the asserted tolerance.
struct MaxTracker
{
  double value = 0.0;
  void update(double v)
  {
    if (!(v <= value))  // also records NaN
      value = v;
  }
};

}  // namespace drb_test
