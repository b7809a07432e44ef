// Oracle tests for rpy.h: R(r), T(r), A(r) and their derivatives.
//
// Oracles (all independent of the closed-form entries in rpy.h):
//   - R as the product Rz(psi) Ry(theta) Rx(phi) of elementary rotations,
//   - Eigen's AngleAxis composition and tf2::Matrix3x3::setRPY (library code),
//   - T assembled from the world directions of the rotation axes,
//   - omega = vee(Rdot R^T), with Rdot by the complex step,
//   - dR in the long form Rz Ry Rx' etc., the complex step and central differences.
//
// Tolerances are absolute on entries that are O(1): every entry of R, T, A,
// dR_k and dA_k is bounded by 1 (or 2 for dA), and the largest entry of R and
// of T is >= 1/sqrt(3), so "absolute" here equals "relative to the largest
// entry" within a factor of 2.
#include <cfloat>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <tf2/LinearMath/Matrix3x3.h>

#include "diff_rigid_body/multibody/rpy.h"
#include "reference/rpy_derivatives.h"
#include "../support/oracles.h"

namespace drb = diff_rigid_body;
using namespace drb_test;

namespace
{
// Closed-form entries (<= 2 products of <= 3 correctly rounded sines/cosines)
// against a product of three matrices: each side is within ~4 eps of the
// exact value, so 8 eps absolute.
constexpr double kRotationTol = 8 * kEps;
// Orthonormality and det: R^T R sums 3 products of entries each off by ~4 eps.
constexpr double kOrthonormalTol = 16 * kEps;
// Complex-step derivatives have no cancellation: the imaginary part carries
// the same few-ulp rounding as a direct evaluation. The 1e-14
// relative bound (~45 ulp) with entries <= 1.
constexpr double kComplexStepTol = 1e-14;
// Central differences, h = 1e-5 rad: truncation h^2/6 |R'''| <= 1.7e-11
// (each coordinate rotates about a fixed unit axis, so |R'''| <= 1) plus
// rounding eps/h = 2.2e-11 per entry. 1e-9 leaves a factor ~25.
constexpr double kFdStep = 1e-5;  // [rad]
constexpr double kFdTol = 1e-9;
// Float kernels against double at the same (float) inputs: a few float ulps
// on O(1) entries.
constexpr double kFloatTol = 8 * FLT_EPSILON;
// Large angles: the exactly wrapped angle is rounded to double (<= 0.5 ulp(pi)
// = 2.2e-16 rad, which moves O(1) entries by as much), glibc's sin/cos reduce
// arguments up to 1e6 to < 1 ulp, plus the kernel's own ~4 eps on each side.
constexpr double kWrappedTol = 16 * kEps;

constexpr int kRandomStates = 1000;

std::vector<Vector6<double>> testStates(std::uint64_t seed)
{
  Random rng(seed);
  std::vector<Vector6<double>> states;
  for (int i = 0; i < kRandomStates; ++i)
    states.push_back(rng.state());
  for (const Vector6<double>& q : gimbalLockStates(rng))
    states.push_back(q);
  // Exact multiples of pi/2 on every axis.
  for (int a = -2; a <= 2; ++a)
    for (int b = -2; b <= 2; ++b)
    {
      Vector6<double> q = Vector6<double>::Zero();
      q[0] = a * kHalfPi;
      q[1] = b * kHalfPi;
      q[2] = (a + b) * kHalfPi;
      states.push_back(q);
    }
  return states;
}

Matrix3<double> kernelR(const Vector6<double>& q)
{
  return drb::rpyToMatrix(q[0], q[1], q[2]);
}

drb::RpyTrig<double> trig(const Vector6<double>& q)
{
  return drb::RpyTrig<double>(q[0], q[1], q[2]);
}
}  // namespace

TEST(Rpy, MatchesElementaryRotationProduct)
{
  MaxTracker err;
  for (const auto& q : testStates(101))
  {
    const double e = maxAbs(kernelR(q) - refRotation(q[0], q[1], q[2]));
    err.update(e);
    ASSERT_LE(e, kRotationTol) << "q = " << q.transpose();
  }
  std::printf("[measured] max |R - Rz Ry Rx| = %.3g eps\n", err.value / kEps);
}

TEST(Rpy, MatchesEigenAngleAxisComposition)
{
  MaxTracker err;
  for (const auto& q : testStates(102))
  {
    const Eigen::Matrix3d R_eigen = (Eigen::AngleAxisd(q[2], Eigen::Vector3d::UnitZ()) *
                                     Eigen::AngleAxisd(q[1], Eigen::Vector3d::UnitY()) *
                                     Eigen::AngleAxisd(q[0], Eigen::Vector3d::UnitX()))
                                        .toRotationMatrix();
    const double e = maxAbs(kernelR(q) - R_eigen);
    err.update(e);
    ASSERT_LE(e, kRotationTol) << "q = " << q.transpose();
  }
  std::printf("[measured] max |R - AngleAxis(z) AngleAxis(y) AngleAxis(x)| = %.3g eps\n", err.value / kEps);
}

// docs/derivation.md, "Coordinates and frames": the convention is
// tf2::Matrix3x3::setRPY(phi, theta, psi) (URDF rpy).
TEST(Rpy, MatchesTf2SetRPY)
{
  MaxTracker err;
  for (const auto& q : testStates(103))
  {
    tf2::Matrix3x3 m;
    m.setRPY(q[0], q[1], q[2]);
    const Matrix3<double> R = kernelR(q);
    double e = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        e = std::max(e, std::abs(R(i, j) - m[i][j]));
    err.update(e);
    ASSERT_LE(e, kRotationTol) << "q = " << q.transpose();
  }
  std::printf("[measured] max |R - tf2 setRPY| = %.3g eps\n", err.value / kEps);
}

TEST(Rpy, IsOrthonormalWithUnitDeterminant)
{
  MaxTracker orth, det;
  for (const auto& q : testStates(104))
  {
    const Matrix3<double> R = kernelR(q);
    const double e_orth = std::max(maxAbs(R.transpose() * R - Matrix3<double>::Identity()),
                                   maxAbs(R * R.transpose() - Matrix3<double>::Identity()));
    const double e_det = std::abs(R.determinant() - 1.0);
    orth.update(e_orth);
    det.update(e_det);
    ASSERT_LE(e_orth, kOrthonormalTol) << "q = " << q.transpose();
    ASSERT_LE(e_det, kOrthonormalTol) << "q = " << q.transpose();
  }
  std::printf("[measured] max |R^T R - I| = %.3g eps, max |det R - 1| = %.3g eps\n", orth.value / kEps,
              det.value / kEps);
}

// The columns of T are the world directions of the X'', Y' and Z axes.
TEST(Rpy, AngularVelocityMatrixColumnsAreTheRotationAxes)
{
  MaxTracker err;
  for (const auto& q : testStates(105))
  {
    const Matrix3<double> T = drb::angularVelocityMatrixWorld(trig(q));
    const Matrix3<double> T_ref = refAngularVelocityMatrix(q[0], q[1], q[2]);
    const double e = maxAbs(T - T_ref);
    err.update(e);
    ASSERT_LE(e, kRotationTol) << "q = " << q.transpose();
    // X'' is the body x axis: R e_x.
    ASSERT_LE(maxAbs(T.col(0) - refRotation(q[0], q[1], q[2]).col(0)), kRotationTol) << "q = " << q.transpose();
  }
  std::printf("[measured] max |T - T(axes)| = %.3g eps\n", err.value / kEps);
}

// omega_world = T rdot must equal vee(Rdot R^T), with Rdot by the complex step
// of the product-form R along rdot. Also omega_body = A rdot = R^T omega.
TEST(Rpy, AngularVelocityMatchesRotationRate)
{
  Random rng(106);
  MaxTracker err_world, err_body;
  for (const auto& q : testStates(106))
  {
    const Eigen::Vector3d rdot = rng.vector(1.0);
    const Matrix3<Complex> Rc = refRotation(Complex(q[0], kComplexStepH * rdot[0]), Complex(q[1], kComplexStepH * rdot[1]),
                                            Complex(q[2], kComplexStepH * rdot[2]));
    const Matrix3<double> Rdot = Rc.imag() / kComplexStepH;
    const Matrix3<double> R = refRotation(q[0], q[1], q[2]);
    const Matrix3<double> W = Rdot * R.transpose();
    // W must be antisymmetric: W = [omega]_x.
    ASSERT_LE(maxAbs(W + W.transpose()), kComplexStepTol * rdot.norm()) << "q = " << q.transpose();
    const Eigen::Vector3d omega_ref = vee(W);
    const Eigen::Vector3d omega = drb::angularVelocityMatrixWorld(trig(q)) * rdot;
    const Eigen::Vector3d omega_body = drb::angularVelocityMatrixBody(trig(q)) * rdot;
    // Relative to |rdot|, which bounds |omega| up to sqrt(3) (unit-norm columns).
    const double e_world = (omega - omega_ref).cwiseAbs().maxCoeff() / rdot.norm();
    const double e_body = (omega_body - R.transpose() * omega_ref).cwiseAbs().maxCoeff() / rdot.norm();
    err_world.update(e_world);
    err_body.update(e_body);
    ASSERT_LE(e_world, kComplexStepTol) << "q = " << q.transpose();
    ASSERT_LE(e_body, kComplexStepTol) << "q = " << q.transpose();
  }
  std::printf("[measured] max |T rdot - vee(Rdot R^T)|/|rdot| = %.3g eps; body (A) %.3g eps\n",
              err_world.value / kEps, err_body.value / kEps);
}

TEST(Rpy, BodyMatrixIsRTransposeTAndIndependentOfPsi)
{
  Random rng(107);
  MaxTracker err;
  for (const auto& q : testStates(107))
  {
    const Matrix3<double> A = drb::angularVelocityMatrixBody(trig(q));
    const Matrix3<double> A_ref =
        refRotation(q[0], q[1], q[2]).transpose() * refAngularVelocityMatrix(q[0], q[1], q[2]);
    const double e = maxAbs(A - A_ref);
    err.update(e);
    ASSERT_LE(e, kRotationTol) << "q = " << q.transpose();
    // Yaw about world Z is a symmetry: A must not read psi at all.
    const Matrix3<double> A_other_psi =
        drb::angularVelocityMatrixBody(drb::RpyTrig<double>(q[0], q[1], rng.uniform(-kPi, kPi)));
    ASSERT_EQ(maxAbs(A - A_other_psi), 0.0);
  }
  std::printf("[measured] max |A - R^T T| = %.3g eps\n", err.value / kEps);
}

TEST(Rpy, RotationDerivativesMatchLongFormComplexStepAndCentralDifferences)
{
  MaxTracker err_long, err_cs, err_fd;
  for (const auto& q : testStates(108))
  {
    const auto dR = drb::rpyToMatrixDerivatives(trig(q));
    const auto dR_long = refRotationDerivatives(q[0], q[1], q[2]);
    for (int k = 0; k < 3; ++k)
    {
      const double e_long = maxAbs(dR[k] - dR_long[k]);
      const Eigen::MatrixXd dR_cs = complexStep(
          [](const Vector6<Complex>& qc) { return drb::rpyToMatrix(drb::RpyTrig<Complex>(qc[0], qc[1], qc[2])); }, q,
          k);
      const double e_cs = maxAbs(dR[k] - dR_cs);
      Vector6<double> qp = q, qm = q;
      qp[k] += kFdStep;
      qm[k] -= kFdStep;
      const Matrix3<double> dR_fd = (kernelR(qp) - kernelR(qm)) / (2 * kFdStep);
      const double e_fd = maxAbs(dR[k] - dR_fd);
      err_long.update(e_long);
      err_cs.update(e_cs);
      err_fd.update(e_fd);
      ASSERT_LE(e_long, kRotationTol) << "k = " << k << ", q = " << q.transpose();
      ASSERT_LE(e_cs, kComplexStepTol) << "k = " << k << ", q = " << q.transpose();
      ASSERT_LE(e_fd, kFdTol) << "k = " << k << ", q = " << q.transpose();
    }
  }
  std::printf("[measured] dR: long form %.3g eps, complex step %.3g eps, central diff %.3g\n", err_long.value / kEps,
              err_cs.value / kEps, err_fd.value);
}

TEST(Rpy, BodyMatrixDerivativesMatchComplexStep)
{
  MaxTracker err_kernel_cs, err_ref_cs;
  for (const auto& q : testStates(109))
  {
    const auto dA = drb::angularVelocityMatrixBodyDerivatives(trig(q));
    for (int k = 0; k < 3; ++k)
    {
      // Complex step through the kernel's A...
      const Eigen::MatrixXd dA_kernel_cs = complexStep(
          [](const Vector6<Complex>& qc) {
            return drb::angularVelocityMatrixBody(drb::RpyTrig<Complex>(qc[0], qc[1], qc[2]));
          },
          q, k);
      // ... and through the independent R^T T.
      const Eigen::MatrixXd dA_ref_cs = complexStep(
          [](const Vector6<Complex>& qc) {
            return Matrix3<Complex>(refRotation(qc[0], qc[1], qc[2]).transpose() *
                                    refAngularVelocityMatrix(qc[0], qc[1], qc[2]));
          },
          q, k);
      const Matrix3<double> expected = k < 2 ? dA[k] : Matrix3<double>::Zero();
      const double e_kernel = maxAbs(expected - dA_kernel_cs);
      const double e_ref = maxAbs(expected - dA_ref_cs);
      err_kernel_cs.update(e_kernel);
      err_ref_cs.update(e_ref);
      ASSERT_LE(e_kernel, kComplexStepTol) << "k = " << k << ", q = " << q.transpose();
      ASSERT_LE(e_ref, kComplexStepTol) << "k = " << k << ", q = " << q.transpose();
    }
  }
  std::printf("[measured] dA vs complex step: kernel A %.3g eps, R^T T %.3g eps\n", err_kernel_cs.value / kEps,
              err_ref_cs.value / kEps);
}

// Angles up to 1e6 rad give the same R, T, A, dR as the exactly wrapped angle.
TEST(Rpy, LargeAnglesMatchWrappedAngles)
{
  Random rng(110);
  MaxTracker err_exact, err_naive;
  for (const double a : largeAngles())
    for (int axis = 0; axis < 3; ++axis)
    {
      Vector6<double> q = rng.state();
      q[axis] = a;
      Vector6<double> q_wrapped = q;
      q_wrapped[axis] = wrapAngleExact(a);
      ASSERT_LE(std::abs(q_wrapped[axis]), kPi + 1e-15);
      const auto t = trig(q), tw = trig(q_wrapped);
      const auto dR = drb::rpyToMatrixDerivatives(t), dRw = drb::rpyToMatrixDerivatives(tw);
      double e = std::max({ maxAbs(drb::rpyToMatrix(t) - drb::rpyToMatrix(tw)),
                            maxAbs(drb::angularVelocityMatrixWorld(t) - drb::angularVelocityMatrixWorld(tw)),
                            maxAbs(drb::angularVelocityMatrixBody(t) - drb::angularVelocityMatrixBody(tw)) });
      for (int k = 0; k < 3; ++k)
        e = std::max(e, maxAbs(dR[k] - dRw[k]));
      err_exact.update(e);
      ASSERT_LE(e, kWrappedTol) << "angle " << a << " on axis " << axis;

      // The naive reduction std::remainder(a, 2 pi) is off by up to
      // |a|/(2 pi) |2 pi - fl(2 pi)| (fl(2 pi) is 2.45e-16 short), so the
      // comparison holds only within that argument-reduction error.
      Vector6<double> q_naive = q;
      q_naive[axis] = std::remainder(a, 2 * kPi);
      const double naive_tol = std::abs(a) / (2 * kPi) * 2.5e-16 + kWrappedTol;
      const double e_naive = maxAbs(drb::rpyToMatrix(t) - drb::rpyToMatrix(trig(q_naive)));
      err_naive.update(e_naive);
      ASSERT_LE(e_naive, naive_tol) << "angle " << a << " on axis " << axis;
    }
  std::printf("[measured] large angles vs exact wrap: %.3g eps; vs naive remainder: %.3g\n", err_exact.value / kEps,
              err_naive.value);
}

// matrixToRpy (used for URDF initial poses) must invert rpyToMatrix for any
// rotation, including generic ones (from AngleAxis/quaternion composition,
// whose entries carry their own rounding) near the gimbal lock.
TEST(Rpy, MatrixToRpyRoundTrip)
{
  // R -> rpy -> R to a few eps, except in the documented lock band
  // (cos theta <= 1e-12, where psi = 0 is chosen): there the error is <= 2 cos theta.
  constexpr double kRoundTripTol = 16 * kEps;
  constexpr double kLockBand = 1e-12;
  // Angles recovered within 1e-12 rad where the map is well conditioned
  // (|cos theta| >= 1e-3: error ~ eps / |cos theta|).
  constexpr double kAngleTol = 1e-12;
  Random rng(112);
  MaxTracker err;
  int recovered = 0;
  std::vector<Vector6<double>> states = testStates(112);
  for (const double theta : gimbalLockThetas())
    for (int n = 0; n < 20; ++n)
    {
      Vector6<double> q = rng.state();
      q[1] = theta;
      states.push_back(q);
    }
  for (const auto& q : states)
  {
    const Eigen::Matrix3d R_generic = (Eigen::AngleAxisd(q[2], Eigen::Vector3d::UnitZ()) *
                                       Eigen::AngleAxisd(q[1], Eigen::Vector3d::UnitY()) *
                                       Eigen::AngleAxisd(q[0], Eigen::Vector3d::UnitX()))
                                          .toRotationMatrix();
    const Eigen::Matrix3d candidates[2] = { kernelR(q), R_generic };
    for (int which = 0; which < 2; ++which)
    {
      const Eigen::Matrix3d& R = candidates[which];
      const Eigen::Vector3d r = drb::matrixToRpy(R);
      ASSERT_TRUE(r.allFinite());
      ASSERT_LE(std::abs(r[0]), kPi);
      ASSERT_LE(std::abs(r[1]), kHalfPi);
      ASSERT_LE(std::abs(r[2]), kPi);
      const double cos_theta = std::hypot(R(0, 0), R(1, 0));
      const double e = maxAbs(drb::rpyToMatrix(r[0], r[1], r[2]) - R);
      if (cos_theta > kLockBand)
      {
        err.update(e);
        ASSERT_LE(e, kRoundTripTol) << "q = " << q.transpose() << ", cos theta = " << cos_theta;
      }
      else
      {
        ASSERT_EQ(r[2], 0.0) << "psi = 0 at the lock";
        ASSERT_LE(e, 2 * cos_theta + kRoundTripTol) << "q = " << q.transpose();
      }
      // In the principal ranges and away from the lock the angles come back.
      if (std::abs(q[0]) < kPi && std::abs(q[1]) < kHalfPi && std::abs(q[2]) < kPi && std::cos(q[1]) >= 1e-3)
      {
        ++recovered;
        ASSERT_NEAR(r[0], q[0], kAngleTol) << "q = " << q.transpose();
        ASSERT_NEAR(r[1], q[1], kAngleTol) << "q = " << q.transpose();
        ASSERT_NEAR(r[2], q[2], kAngleTol) << "q = " << q.transpose();
      }
    }
  }
  EXPECT_GT(recovered, 500);
  std::printf("[measured] rpyToMatrix(matrixToRpy(R)) - R: %.3g eps outside the lock band\n", err.value / kEps);
}

// sinCos (the vectorised sine/cosine of the batched kernels): documented
// absolute error "about 2 ulp of 1" on the fast path (|x| < 1.6e6), glibc
// beyond it and for non-finite values. Checked against 256-bit MPFR at the
// exact double x, including the doubles nearest multiples of pi/2 (where the
// argument reduction cancels), the gimbal-lock angles, every count modulo
// the block size and the fall-back blocks.
TEST(Rpy, SinCosMatchesMpfr)
{
  constexpr double kSinCosAbsTol = 2 * kEps;  // measured 0.68 eps
  Random rng(113);
  std::vector<double> x;
  for (int i = 0; i < 8000; ++i)
    x.push_back(rng.uniform(-drb::kSinCosFastLimit, drb::kSinCosFastLimit));
  for (int i = 0; i < 8000; ++i)
    x.push_back(rng.uniform(-10.0, 10.0));
  for (int i = 0; i < 2000; ++i)
  {
    // The double nearest n pi/2, and its neighbours.
    const long n = i < 1000 ? i - 500 : rng.integer(-1000000, 1000000);
    double v = (n * mpfr::const_pi(256) / 2).toDouble();
    x.push_back(v);
    x.push_back(std::nextafter(v, 1e300));
    x.push_back(std::nextafter(v, -1e300));
  }
  for (const double t : gimbalLockThetas())
    x.push_back(t);
  for (const double a : largeAngles())
    x.push_back(a);
  for (const double v : { 0.0, -0.0, 1e-300, std::nextafter(drb::kSinCosFastLimit, 0.0), drb::kSinCosFastLimit, 1e7,
                          -3e9, 1e300 })
    x.push_back(v);
  std::vector<mpfr::mpreal> sin_ref, cos_ref;
  for (const double v : x)
  {
    sin_ref.push_back(mpfr::sin(mpfr::mpreal(v, 256)));
    cos_ref.push_back(mpfr::cos(mpfr::mpreal(v, 256)));
  }
  MaxTracker err;
  // Every tail length: the last count mod kSinCosLanes values are padded.
  for (std::size_t tail = 0; tail < static_cast<std::size_t>(drb::kSinCosLanes); ++tail)
  {
    const std::size_t count = x.size() - tail;
    std::vector<double> s(count + 1, -999.0), c(count + 1, -999.0);
    drb::sinCos(x.data(), count, s.data(), c.data());
    ASSERT_EQ(s[count], -999.0);
    ASSERT_EQ(c[count], -999.0);
    for (std::size_t i = 0; i < count; ++i)
    {
      const double e = std::max(mpfr::abs(mpfr::mpreal(s[i], 256) - sin_ref[i]).toDouble(),
                                mpfr::abs(mpfr::mpreal(c[i], 256) - cos_ref[i]).toDouble());
      err.update(e);
      ASSERT_LE(e, kSinCosAbsTol) << "x = " << x[i] << ", count " << count;
    }
  }
  // Non-finite values give NaN and leave their block's other values right.
  std::vector<double> y = { 0.5, std::numeric_limits<double>::infinity(), -1.0, std::numeric_limits<double>::quiet_NaN(),
                            2.0, 3.0, 4.0, 5.0, 6.0 };
  std::vector<double> s(y.size()), c(y.size());
  drb::sinCos(y.data(), y.size(), s.data(), c.data());
  EXPECT_TRUE(std::isnan(s[1]) && std::isnan(c[1]) && std::isnan(s[3]) && std::isnan(c[3]));
  for (const std::size_t i : { 0, 2, 4, 5, 6, 7, 8 })
  {
    EXPECT_NEAR(s[i], std::sin(y[i]), kSinCosAbsTol);
    EXPECT_NEAR(c[i], std::cos(y[i]), kSinCosAbsTol);
  }
  std::printf("[measured] sinCos vs MPFR: %.3g eps absolute\n", err.value / kEps);
}

TEST(Rpy, FloatAgreesWithDouble)
{
  MaxTracker err;
  for (const auto& qd : testStates(111))
  {
    const Vector6<float> qf = qd.cast<float>();
    const Vector6<double> q = qf.cast<double>();  // the same inputs in both precisions
    const drb::RpyTrig<float> tf(qf[0], qf[1], qf[2]);
    const auto t = trig(q);
    double e = std::max({ maxAbs(drb::rpyToMatrix(tf).cast<double>() - drb::rpyToMatrix(t)),
                          maxAbs(drb::angularVelocityMatrixWorld(tf).cast<double>() - drb::angularVelocityMatrixWorld(t)),
                          maxAbs(drb::angularVelocityMatrixBody(tf).cast<double>() - drb::angularVelocityMatrixBody(t)) });
    const auto dRf = drb::rpyToMatrixDerivatives(tf);
    const auto dR = drb::rpyToMatrixDerivatives(t);
    const auto dAf = drb::angularVelocityMatrixBodyDerivatives(tf);
    const auto dA = drb::angularVelocityMatrixBodyDerivatives(t);
    for (int k = 0; k < 3; ++k)
      e = std::max(e, maxAbs(dRf[k].cast<double>() - dR[k]));
    for (int k = 0; k < 2; ++k)
      e = std::max(e, maxAbs(dAf[k].cast<double>() - dA[k]));
    err.update(e);
    ASSERT_LE(e, kFloatTol) << "q = " << q.transpose();
  }
  std::printf("[measured] float vs double: %.3g float eps\n", err.value / FLT_EPSILON);
}
