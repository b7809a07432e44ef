// Gimbal lock: theta = +-pi/2 and +-pi/2 +- 10^-k, k = 1..16 (docs/derivation.md,
// "Mass matrix" and "Hard cases").
//
// At the lock the X'' axis (T's first column, (cos th cos psi, cos th sin psi,
// -sin th)) lines up with Z (its third), so:
//   - T and the rotation block of J lose rank (rank 2); n = (1, 0, sin th) is
//     the null direction and |T n| = |cos th| exactly (in exact arithmetic);
//   - det(T) = cos th, det(A^T I_b A) = cos^2 th det(I_b), M has rank 5;
//   - everything stays finite, and gimbalLockCosine reports cos th.
// The reference for cos th is MPFR (256 bits) at the exact double theta.
#include <unsupported/Eigen/MPRealSupport>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "diff_rigid_body/algorithm/free_body/mass_matrix.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"
#include "reference/gimbal_lock.h"
#include "reference/rpy_derivatives.h"
#include "reference/vertex_kernels.h"
#include "../support/oracles.h"

namespace drb = diff_rigid_body;
using namespace drb_test;
using mpfr::mpreal;

namespace
{
// Singular values from JacobiSVD are accurate to a few eps times the largest
// one (absolute), so small singular values are checked to 8 eps * sigma_1.
constexpr double kSvdAbsTol = 8 * kEps;
// Eigenvalues of the symmetric 6x6 M: backward stable, |error| <= c eps |M|;
// together with M's own few-ulp error, 16 eps * lambda_max.
constexpr double kEigAbsTol = 16 * kEps;
// "Clearly positive": the other singular values / eigenvalues stay above this
// fraction of the largest one. For T at the lock they are sqrt(2), 1, 0; for M
// with I_b eigenvalues in [1, 2.5] and m = 2 the nonzero ones are >= 1.
constexpr double kClearlyPositive = 0.1;
// det of the 3x3 double angular block vs cos^2 th det(I_b) (MPFR): the
// determinant of a matrix with entries off by a few ulp of max|I_b| moves by
// ~ 6 * (few ulp) * max|I_b|^3; 64 eps * max|I_b|^3 absolute.
constexpr double kDetAbsTol = 64 * kEps;
// The two 256-bit evaluations of the same identity: 2^-256 ~ 1e-77.
constexpr double kMpfrTol = 1e-70;

/// cos(theta) at the exact double theta, correctly rounded (256-bit MPFR).
double cosExact(double theta)
{
  return mpfr::cos(mpreal(theta, 256)).toDouble();
}

std::vector<Vector6<double>> lockStates(std::uint64_t seed, int per_theta)
{
  Random rng(seed);
  std::vector<Vector6<double>> states;
  for (const double theta : gimbalLockThetas())
    for (int n = 0; n < per_theta; ++n)
    {
      Vector6<double> q = rng.state();
      q[1] = theta;
      if (n == 0)
        q[0] = q[2] = 0;  // phi = psi = 0 as well
      states.push_back(q);
    }
  return states;
}

Matrix3<double> bodyInertia(Random& rng)
{
  const Matrix3<double> Q = rng.rotation();
  const Matrix3<double> I = Q * Eigen::Vector3d(1.0, 2.0, 2.5).asDiagonal() * Q.transpose();
  return (I + I.transpose()) / 2.0;
}

drb::RpyTrig<double> trig(const Vector6<double>& q)
{
  return drb::RpyTrig<double>(q[0], q[1], q[2]);
}
}  // namespace

TEST(GimbalLock, AllOutputsFinite)
{
  Random rng(1101);
  for (const Vector6<double>& q : lockStates(1101, 4))
    for (const double scale : vertexScales())
    {
      const auto t = trig(q);
      ASSERT_TRUE(drb::rpyToMatrix(t).allFinite());
      ASSERT_TRUE(drb::angularVelocityMatrixWorld(t).allFinite());
      ASSERT_TRUE(drb::angularVelocityMatrixBody(t).allFinite());
      for (const auto& dR : drb::rpyToMatrixDerivatives(t))
        ASSERT_TRUE(dR.allFinite());
      for (const auto& dA : drb::angularVelocityMatrixBodyDerivatives(t))
        ASSERT_TRUE(dA.allFinite());

      drb::Matrix3X<double> vertices(3, 6);
      for (int i = 0; i < 6; ++i)
        vertices.col(i) = rng.vector(scale);
      const drb::BodyPose<double> pose(q);
      std::vector<double> positions(18), jacobians(108), g(18);
      drb::vertexPositionsAndJacobians(pose, vertices, {}, positions.data(), jacobians.data());
      for (const double x : positions)
        ASSERT_TRUE(std::isfinite(x));
      for (const double x : jacobians)
        ASSERT_TRUE(std::isfinite(x));
      for (double& x : g)
        x = rng.uniform(-1, 1);
      ASSERT_TRUE(drb::backpropagateVertexGradients(pose, vertices, {}, g.data()).allFinite());

      const Matrix3<double> I = bodyInertia(rng) * scale * scale;
      ASSERT_TRUE(drb::massMatrix(q, 2.0, I).allFinite());
      for (const auto& dM : drb::massMatrixDerivatives(q, I))
        ASSERT_TRUE(dM.allFinite());
      ASSERT_TRUE(std::isfinite(drb::gimbalLockCosine(q[1])));
    }
}

TEST(GimbalLock, RotationBlockHasRankTwo)
{
  Random rng(1102);
  MaxTracker err_sigma3, err_null, err_stack;
  int exact_locks = 0;
  for (const Vector6<double>& q : lockStates(1102, 4))
  {
    const double c = cosExact(q[1]);
    const Matrix3<double> T = drb::angularVelocityMatrixWorld(trig(q));
    const Eigen::Vector3d s = Eigen::JacobiSVD<Matrix3<double>>(T).singularValues();
    // sigma_1 sigma_2 sigma_3 = |det T| = |cos th|: the third singular value
    // follows cos th down to zero while the other two stay put.
    const double e3 = std::abs(s[2] - std::abs(c) / (s[0] * s[1])) / s[0];
    err_sigma3.update(e3);
    ASSERT_LE(e3, kSvdAbsTol) << "theta = " << q[1];
    ASSERT_GE(s[1], kClearlyPositive * s[0]) << "theta = " << q[1];
    if (std::abs(c) < 1e-15)
    {
      ++exact_locks;
      ASSERT_LE(s[2], kSvdAbsTol * s[0]) << "rank 2 at theta = " << q[1];
    }
    // The null direction: rates (1, 0, sin th) turn phi and psi against each
    // other about the same axis; the resulting |omega| is |cos th|.
    const Eigen::Vector3d n(1.0, 0.0, std::sin(q[1]));
    const double e_null = std::abs((T * n).norm() - std::abs(c));
    err_null.update(e_null);
    ASSERT_LE(e_null, 4 * kEps * std::abs(c) + 4 * kEps * kEps) << "theta = " << q[1];

    // Stacked rotation blocks of J for 8 vertices: (24 x 3) = L T with
    // L = stacked -[R p0_i]_x, so sigma_3(J stack) <= sigma_1(L) sigma_3(T).
    const drb::BodyPose<double> pose(q);
    Eigen::Matrix<double, 24, 3> J_stack, L;
    for (int i = 0; i < 8; ++i)
    {
      const Vector3<double> p0 = rng.vector(1.0);
      J_stack.middleRows<3>(3 * i) = drb::vertexJacobian(pose, p0).leftCols<3>();
      L.middleRows<3>(3 * i) = -skew(Vector3<double>(refRotation(q[0], q[1], q[2]) * p0));
    }
    const Eigen::Vector3d sj = Eigen::JacobiSVD<Eigen::Matrix<double, 24, 3>>(J_stack).singularValues();
    const double sl = Eigen::JacobiSVD<Eigen::Matrix<double, 24, 3>>(L).singularValues()[0];
    const double bound = sl * std::abs(c) / (s[0] * s[1]);
    err_stack.update(std::max(0.0, sj[2] - bound) / sj[0]);
    ASSERT_LE(sj[2], bound + kSvdAbsTol * sj[0]) << "theta = " << q[1];
    ASSERT_GE(sj[1], kClearlyPositive * sj[0]) << "theta = " << q[1];
  }
  EXPECT_GE(exact_locks, 8);
  std::printf("[measured] T: |sigma_3 - |cos th|/(sigma_1 sigma_2)| <= %.3g eps sigma_1; | |T n| - |cos th| | <= %.3g; "
              "stacked J sigma_3 above its bound by <= %.3g eps sigma_1 (%d exact locks)\n",
              err_sigma3.value / kEps, err_null.value, err_stack.value / kEps, exact_locks);
}

TEST(GimbalLock, MassMatrixHasRankFive)
{
  Random rng(1103);
  MaxTracker smallest, null_residual;
  int locked = 0;
  for (const Vector6<double>& q : lockStates(1103, 4))
  {
    const Matrix3<double> I = bodyInertia(rng);
    const Matrix6<double> M = drb::massMatrix(q, 2.0, I);
    const Eigen::Matrix<double, 6, 1> lambda = Eigen::SelfAdjointEigenSolver<Matrix6<double>>(M).eigenvalues();
    // Five eigenvalues clearly positive at every theta of the list.
    ASSERT_GE(lambda[1], kClearlyPositive * lambda[5]) << "theta = " << q[1];
    // The smallest one is O(cos^2 th): it vanishes (to rounding) at the lock.
    const double c = cosExact(q[1]);
    if (isNumericallyLocked(q[1]))
    {
      ++locked;
      smallest.update(std::abs(lambda[0]) / lambda[5]);
      ASSERT_LE(std::abs(lambda[0]), kEigAbsTol * lambda[5]) << "theta = " << q[1];
    }
    else if (std::abs(c) >= 1e-5)
    {
      // cos^2 th >= 1e-10: lambda_min ~ 1e-11 lambda_max, far above rounding.
      ASSERT_GT(lambda[0], kEigAbsTol * lambda[5]) << "theta = " << q[1];
    }
    // The null direction (1, 0, sin th, 0, 0, 0): |M n| = O(|cos th|).
    Vector6<double> n = Vector6<double>::Zero();
    n[0] = 1;
    n[2] = std::sin(q[1]);
    const double residual = (M * n).norm() / lambda[5];
    null_residual.update(std::max(0.0, residual - 4 * std::abs(c)));
    ASSERT_LE(residual, 4 * std::abs(c) + 16 * kEps) << "theta = " << q[1];
  }
  EXPECT_GE(locked, 16);
  std::printf("[measured] M at the lock (%d states): |lambda_min| / lambda_max <= %.3g eps; "
              "|M n| above 4|cos th| by <= %.3g\n",
              locked, smallest.value / kEps, null_residual.value);
}

TEST(GimbalLock, AngularDeterminantIsCosSquaredDetInertia)
{
  mpreal::set_default_prec(256);
  Random rng(1104);
  std::vector<Vector6<double>> states = lockStates(1104, 2);
  for (int s = 0; s < 200; ++s)
    states.push_back(rng.state());
  MaxTracker err_double, err_mp;
  for (const Vector6<double>& q : states)
  {
    Matrix3<double> I = bodyInertia(rng) * rng.logUniform(1e-6, 1e6);
    if (rng.integer(0, 3) == 0)
      I = Eigen::Vector3d(1e-9, 1.0, 1.0).asDiagonal();  // thin rod
    const Eigen::Matrix<mpreal, 6, 1> q_mp = q.cast<mpreal>();
    const Eigen::Matrix<mpreal, 3, 3> I_mp = I.cast<mpreal>();
    const mpreal c = mpfr::cos(q_mp[1]);
    const mpreal det_ref = c * c * I_mp.determinant();
    const double scale3 = std::pow(maxAbs(I), 3);

    // The identity itself, through the kernel in 256 bits.
    const Eigen::Matrix<mpreal, 6, 6> M_mp = drb::massMatrix(q_mp, mpreal(2.0), I_mp);
    const mpreal det_mp = M_mp.topLeftCorner<3, 3>().determinant();
    const double e_mp = mpfr::abs(det_mp - det_ref).toDouble() / scale3;
    err_mp.update(e_mp);
    ASSERT_LE(e_mp, kMpfrTol) << "theta = " << q[1];

    // The double kernel: det of its angular block within rounding of |I|^3.
    const Matrix6<double> M = drb::massMatrix(q, 2.0, I);
    const double e = std::abs(M.topLeftCorner<3, 3>().determinant() - det_ref.toDouble()) / scale3;
    err_double.update(e);
    ASSERT_LE(e, kDetAbsTol) << "theta = " << q[1];
  }
  // Exactly pi/2 (not the double nearest): det = 0 to 256-bit rounding.
  for (const int sign : { 1, -1 })
  {
    Eigen::Matrix<mpreal, 6, 1> q_mp = Eigen::Matrix<mpreal, 6, 1>::Zero();
    q_mp[0] = mpreal(0.3);
    q_mp[1] = sign * mpfr::const_pi() / 2;
    q_mp[2] = mpreal(-1.1);
    const Eigen::Matrix<mpreal, 3, 3> I_mp = bodyInertia(rng).cast<mpreal>();
    const Eigen::Matrix<mpreal, 6, 6> M_mp = drb::massMatrix(q_mp, mpreal(2.0), I_mp);
    EXPECT_LE(mpfr::abs(M_mp.topLeftCorner<3, 3>().determinant()).toDouble(), kMpfrTol);
    EXPECT_LE(mpfr::abs(drb::gimbalLockCosine(q_mp[1])).toDouble(), kMpfrTol);
  }
  std::printf("[measured] det(A^T I A) vs cos^2 th det I: double %.3g eps |I|^3, 256-bit %.3g |I|^3\n",
              err_double.value / kEps, err_mp.value);
}

TEST(GimbalLock, CosineReportedCorrectly)
{
  Random rng(1105);
  std::vector<double> thetas = gimbalLockThetas();
  for (const double a : largeAngles())
    thetas.push_back(a);
  for (int s = 0; s < 1000; ++s)
    thetas.push_back(rng.uniform(-kPi, kPi));
  MaxTracker err;
  for (const double theta : thetas)
  {
    const double c = drb::gimbalLockCosine(theta);
    // Error against the 256-bit cosine, in ulps of the result; glibc's cos is
    // documented as < 1 ulp (correctly rounded means <= 0.5 ulp).
    const double e = (mpfr::abs(mpreal(c, 256) - mpfr::cos(mpreal(theta, 256))) / ulp(c)).toDouble();
    err.update(e);
    ASSERT_LT(e, 1.0) << "theta = " << theta;
    // Float: cosf within 1 float ulp of the cosine of the same float angle.
    const float theta_f = static_cast<float>(theta);
    const float cf = drb::gimbalLockCosine(theta_f);
    const double ref_f = cosExact(theta_f);
    ASSERT_LE(std::abs(cf - ref_f), std::nextafter(std::abs(static_cast<float>(ref_f)), 2.0f) -
                                        std::abs(static_cast<float>(ref_f)))
        << "theta = " << theta_f;
  }
  // Near the lock the cosine is the signed distance to it: with x = fl(base +- d)
  // and e = x - base (exact, Sterbenz), cos x = cos(base) cos e - sin(base) sin e,
  // i.e. -+ sin e plus the 6.1e-17 by which fl(pi/2) falls short of pi/2.
  for (int k = 1; k <= 16; ++k)
  {
    const double d = std::pow(10.0, -k);
    for (const double base : { kHalfPi, -kHalfPi })
      for (const double x : { base + d, base - d })
      {
        const double e = x - base;
        const double expected = std::cos(base) * std::cos(e) - std::sin(base) * std::sin(e);
        EXPECT_NEAR(drb::gimbalLockCosine(x), expected, 4 * kEps * std::abs(expected)) << "x = " << x;
        // Sign: past +pi/2 (or before -pi/2) the cosine is negative.
        if (std::abs(e) > 1e-15)
        {
          EXPECT_EQ(drb::gimbalLockCosine(x) < 0, std::abs(x) > kHalfPi) << "x = " << x;
        }
      }
  }
  EXPECT_LE(std::abs(drb::gimbalLockCosine(kHalfPi)), 1e-16);
  EXPECT_LE(std::abs(drb::gimbalLockCosine(-kHalfPi)), 1e-16);
  std::printf("[measured] gimbalLockCosine vs MPFR cos: %.3g ulp\n", err.value);
}
