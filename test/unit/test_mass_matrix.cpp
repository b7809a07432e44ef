// Oracle tests for mass_matrix.h: M(q) = blockdiag(A^T I_b A, m I3) and dM/dq.
//
// Oracles:
//   - the particle identity M = sum_i m_i J_i^T J_i for point masses with
//     sum m_i p0_i = 0, m = sum m_i and I_b from the particle sum (seed eq. 17)
//     evaluated here (docs/derivation.md, "Identities used as test oracles"), with
//     the long-form J of oracles.h (and, to tie the kernels together, the
//     kernel's vertexJacobian);
//   - 256-bit MPFR: the same templated kernel run in mpfr::mpreal AND an
//     independent mpreal evaluation of blockdiag(T^T R I_b R^T T, m I3);
//   - dM/dq: the complex step through massMatrix<std::complex<double>> and
//     through the independent T^T R I_b R^T T, and central differences.
//
// Error measure: the angular block is compared relative to its own largest
// entry (stricter than relative to max|M|, which the mass can dominate by up
// to 1e15 in the extreme cases: an error of k ulp of max|M_ang| is at most k
// ulp of max|M|); the translation block must be exactly m I3.
#include <unsupported/Eigen/MPRealSupport>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/algorithm/free_body/mass_matrix.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"
#include "reference/vertex_kernels.h"
#include "../support/oracles.h"

namespace drb = diff_rigid_body;
using namespace drb_test;
using mpfr::mpreal;

namespace
{
// Double kernel vs the 256-bit reference, in ulps of the largest entry of the
// angular block (ulp = spacing of doubles at that entry). Each entry of
// A^T I_b A sums 9 products of (rounded sines and cosines) x (inertia), with
// ~6 roundings on the longest path. Measured: 3.5 ulp worst over this test's
// cases; in a separate sweep of 200,000 random states/inertias the
// distribution was 80% <= 1 ulp, 0.02% > 3 ulp, worst 4.1 ulp (a max entry
// just below a power of 2, where one ulp is half its relative size). We assert
// 6 ulp.
constexpr double kMpfrUlps = 6;
// The two 256-bit evaluations (kernel in mpreal vs T^T R I R^T T in mpreal)
// must agree far below double resolution: 2^-256 ~ 1e-77, allow 1e-70.
constexpr double kMpfrSelfTol = 1e-70;
// Particle identity: sum over up to 2x8 particles of m_i J_i^T J_i against
// A^T I_b A with I_b summed the same way; a few eps of the angular block's
// largest entry on each side. 1e-14 ~ 45 eps.
constexpr double kParticleTol = 1e-14;
// Complex step of M: no cancellation, a few ulp of the angular block's largest
// entry (|A|, |dA| = O(1), so entries of dM are bounded by ~4 max|I_b|).
constexpr double kComplexStepTol = 1e-14;
// Central differences, h = 1e-5 rad: truncation h^2/6 |M'''| with
// |M'''| <= ~16 max|M_ang| (third derivatives of products of two O(1)
// trigonometric matrices) gives <= 3e-10; rounding eps max|M_ang| / h = 2e-11.
// 1e-9 relative to the largest entry of the angular block.
constexpr double kFdStep = 1e-5;  // [rad]
constexpr double kFdTol = 1e-9;
// Float kernels vs double at the same float inputs, relative to the largest
// entry of the angular block.
constexpr double kFloatTol = 8 * FLT_EPSILON;

constexpr int kRandomStates = 1000;

using MatrixMp3 = Eigen::Matrix<mpreal, 3, 3>;
using MatrixMp6 = Eigen::Matrix<mpreal, 6, 6>;
using VectorMp6 = Eigen::Matrix<mpreal, 6, 1>;

template <typename Derived>
Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> toDouble(
    const Eigen::MatrixBase<Derived>& m)
{
  return m.unaryExpr([](const mpreal& x) { return x.toDouble(); });
}

struct Body
{
  double mass;        // [kg]
  Matrix3<double> I;  // about the COM, body axes [kg m^2]
  const char* kind;
};

/// A body made of point masses with its COM at the origin.
struct ParticleBody
{
  std::vector<Vector3<double>> points;
  std::vector<double> masses;
  double mass = 0;
  Matrix3<double> inertia;
};

/// Symmetric pairs (p, -p) with equal masses: sum m_i p_i = 0 exactly, and
/// pairwise accumulation keeps the cross block of sum m_i J^T J exactly zero.
/// With `offset_com` the particles are instead arbitrary and the COM is
/// subtracted (sum m_i p_i = 0 up to rounding).
ParticleBody particleBody(Random& rng, bool offset_com)
{
  ParticleBody b;
  const int pairs = rng.integer(2, 8);
  const double size = rng.logUniform(1e-3, 1e2);
  for (int k = 0; k < pairs; ++k)
  {
    const Vector3<double> p = rng.vector(size);
    const double m = rng.logUniform(1e-2, 1e2);
    b.points.push_back(p);
    b.masses.push_back(m);
    b.points.push_back(offset_com ? Vector3<double>(rng.vector(size)) : Vector3<double>(-p));
    b.masses.push_back(offset_com ? rng.logUniform(1e-2, 1e2) : m);
  }
  for (const double m : b.masses)
    b.mass += m;
  if (offset_com)
  {
    Vector3<double> com = Vector3<double>::Zero();
    for (std::size_t i = 0; i < b.points.size(); ++i)
      com += b.masses[i] * b.points[i];
    com /= b.mass;
    for (auto& p : b.points)
      p -= com;
  }
  b.inertia = particleInertia(b.points, b.masses);  // seed eq. (17)
  return b;
}

/// Bodies across the hard cases: masses 1e-9 .. 1e9 kg, inertias across 24
/// decades, thin rods diag(eps, I, I) in body axes and rotated.
std::vector<Body> hardBodies(Random& rng)
{
  std::vector<Body> bodies;
  for (const double m : { 1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6, 1e9 })
    bodies.push_back({ m, rng.inertia(m * rng.logUniform(1e-3, 1e3)), "extreme mass" });
  for (const double I : { 1e-12, 1e-3, 1.0, 1e3, 1e12 })
    for (const double thin : { 1e-16, 1e-12, 1e-6, 1e-3 })
    {
      const Matrix3<double> rod = Eigen::Vector3d(thin * I, I, I).asDiagonal();
      bodies.push_back({ rng.logUniform(1e-9, 1e9), rod, "thin rod" });
      const Matrix3<double> Q = rng.rotation();
      const Matrix3<double> rotated = Q * rod * Q.transpose();
      bodies.push_back({ rng.logUniform(1e-9, 1e9), Matrix3<double>((rotated + rotated.transpose()) / 2.0),
                         "rotated thin rod" });
    }
  // Isotropic and axisymmetric.
  bodies.push_back({ 2.0, Matrix3<double>::Identity() * 0.4, "sphere" });
  bodies.push_back({ 3.0, Matrix3<double>(Eigen::Vector3d(1.0, 1.0, 0.5).asDiagonal()), "disc" });
  return bodies;
}

std::vector<Vector6<double>> hardStates(Random& rng)
{
  std::vector<Vector6<double>> states = gimbalLockStates(rng);
  for (const double a : largeAngles())
    for (int axis = 0; axis < 3; ++axis)
    {
      Vector6<double> q = rng.state();
      q[axis] = a;
      states.push_back(q);
    }
  return states;
}

double angularScale(const Matrix6<double>& M)
{
  return maxAbs(M.topLeftCorner<3, 3>());
}

Matrix6<double> kernelM(const Vector6<double>& q, const Body& b)
{
  return drb::massMatrix(q, b.mass, b.I);
}

/// The translation block is m I3 exactly and the cross blocks exactly zero.
void expectExactTranslationBlock(const Matrix6<double>& M, double mass)
{
  Matrix6<double> expected_lower = Matrix6<double>::Zero();
  expected_lower.bottomRightCorner<3, 3>() = mass * Matrix3<double>::Identity();
  Matrix6<double> lower = M;
  lower.topLeftCorner<3, 3>().setZero();
  EXPECT_EQ(maxAbs(lower - expected_lower), 0.0) << "mass " << mass;
}

struct MpfrResult
{
  double ulps;      // |M_double - M_256| in ulps of the angular block's largest entry
  double self_rel;  // |kernel<mpreal> - independent mpreal| / max entry
};

MpfrResult compareWithMpfr(const Vector6<double>& q, const Body& b)
{
  const VectorMp6 q_mp = q.cast<mpreal>();
  const mpreal m_mp(b.mass);
  const MatrixMp3 I_mp = b.I.cast<mpreal>();
  const MatrixMp6 M_kernel_mp = drb::massMatrix(q_mp, m_mp, I_mp);
  const MatrixMp6 M_indep_mp = refMassMatrix(q_mp, m_mp, I_mp);
  const Matrix6<double> M_ref = toDouble(M_kernel_mp);
  const mpreal self_err = (M_kernel_mp - M_indep_mp).cwiseAbs().maxCoeff();
  const Matrix6<double> M = kernelM(q, b);
  expectExactTranslationBlock(M, b.mass);
  // The error is taken in 256 bits, then rounded.
  const mpreal err = (M.topLeftCorner<3, 3>().cast<mpreal>() - M_kernel_mp.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff();
  const double scale = angularScale(M_ref);
  return { err.toDouble() / ulp(scale), self_err.toDouble() / maxAbs(M_ref) };
}
}  // namespace

// ---------------------------------------------------------------------------

TEST(MassMatrix, MatchesParticleIdentity)
{
  Random rng(601);
  MaxTracker err_long, err_kernel_J, err_energy;
  for (int s = 0; s < kRandomStates / 5; ++s)
  {
    const bool offset_com = s % 4 == 3;
    const ParticleBody b = particleBody(rng, offset_com);
    for (int n = 0; n < 5; ++n)
    {
      const Vector6<double> q = rng.state();
      const Matrix6<double> M = drb::massMatrix(q, b.mass, b.inertia);
      const drb::BodyPose<double> pose(q);
      Matrix6<double> M_particles = Matrix6<double>::Zero(), M_particles_kernel_J = Matrix6<double>::Zero();
      const Vector6<double> qdot = rng.vector6(1.0);
      double energy_particles = 0;
      for (std::size_t i = 0; i < b.points.size(); ++i)
      {
        const Matrix36<double> J = refJacobian(q, b.points[i]);
        M_particles += b.masses[i] * J.transpose() * J;
        const Matrix36<double> J_kernel = drb::vertexJacobian(pose, b.points[i]);
        M_particles_kernel_J += b.masses[i] * J_kernel.transpose() * J_kernel;
        energy_particles += 0.5 * b.masses[i] * (J * qdot).squaredNorm();
      }
      const double scale = angularScale(M);
      // With exact pairs the cross and translation blocks are exact; with a
      // subtracted COM the cross block is sum m_i (dR p_i) ~ eps sum m_i |p_i|,
      // so there we measure relative to max|M| instead.
      const double denom = offset_com ? maxAbs(M) : scale;
      const double e_long = maxAbs(M - M_particles) / denom;
      const double e_kernel = maxAbs(M - M_particles_kernel_J) / denom;
      const double energy = 0.5 * qdot.dot(M * qdot);
      const double e_energy = std::abs(energy - energy_particles) / energy_particles;
      err_long.update(e_long);
      err_kernel_J.update(e_kernel);
      err_energy.update(e_energy);
      ASSERT_LE(e_long, kParticleTol) << "q = " << q.transpose() << ", " << b.points.size() << " particles";
      ASSERT_LE(e_kernel, kParticleTol) << "q = " << q.transpose();
      ASSERT_LE(e_energy, kParticleTol) << "q = " << q.transpose();
      if (!offset_com)
        expectExactTranslationBlock(M_particles, b.mass);
    }
  }
  std::printf("[measured] M vs sum m_i J_i^T J_i: %.3g eps (long-form J), %.3g eps (kernel J); "
              "kinetic energy %.3g eps\n",
              err_long.value / kEps, err_kernel_J.value / kEps, err_energy.value / kEps);
}

TEST(MassMatrix, ThinRodOfParticles)
{
  // Particles on the body x axis with a tiny transverse spread: I_xx ~ 1e-12
  // relative, the edge of the triangle inequality.
  Random rng(602);
  ParticleBody b;
  for (int k = 1; k <= 5; ++k)
    for (const double sign : { 1.0, -1.0 })
    {
      b.points.push_back(Vector3<double>(sign * k * 0.2, sign * 1e-6 * k, -sign * 1e-6));
      b.masses.push_back(0.7);
    }
  for (const double m : b.masses)
    b.mass += m;
  b.inertia = particleInertia(b.points, b.masses);
  ASSERT_LT(b.inertia(0, 0), 1e-10 * b.inertia(1, 1));
  MaxTracker err;
  for (int s = 0; s < 200; ++s)
  {
    Vector6<double> q = rng.state();
    if (s < 66)
      q[1] = gimbalLockThetas()[s];
    const Matrix6<double> M = drb::massMatrix(q, b.mass, b.inertia);
    Matrix6<double> M_particles = Matrix6<double>::Zero();
    for (std::size_t i = 0; i < b.points.size(); ++i)
    {
      const Matrix36<double> J = refJacobian(q, b.points[i]);
      M_particles += b.masses[i] * J.transpose() * J;
    }
    const double e = maxAbs(M - M_particles) / angularScale(M);
    err.update(e);
    ASSERT_LE(e, kParticleTol) << "q = " << q.transpose();
  }
  std::printf("[measured] thin rod of particles: %.3g eps\n", err.value / kEps);
}

TEST(MassMatrix, MatchesMpfr256)
{
  mpreal::set_default_prec(256);
  Random rng(603);
  MaxTracker ulps, self;
  auto check = [&](const Vector6<double>& q, const Body& b) {
    const MpfrResult r = compareWithMpfr(q, b);
    ulps.update(r.ulps);
    self.update(r.self_rel);
    ASSERT_LE(r.self_rel, kMpfrSelfTol) << b.kind << ", q = " << q.transpose();
    ASSERT_LE(r.ulps, kMpfrUlps) << b.kind << ", mass " << b.mass << ", q = " << q.transpose() << "\nI_b =\n" << b.I;
  };
  for (int s = 0; s < kRandomStates; ++s)
  {
    const double m = rng.logUniform(1e-9, 1e9);
    check(rng.state(), { m, rng.inertia(m * rng.logUniform(1e-4, 1e4)), "random" });
  }
  const auto bodies = hardBodies(rng);
  for (const Vector6<double>& q : hardStates(rng))
    for (const Body& b : bodies)
      check(q, b);
  for (int s = 0; s < 50; ++s)
    for (const Body& b : bodies)
      check(rng.state(), b);
  std::printf("[measured] M (double) vs 256-bit MPFR: max %.3g ulp of the angular block's largest entry; "
              "kernel<mpreal> vs T^T R I R^T T in mpreal: %.3g relative\n",
              ulps.value, self.value);
}

TEST(MassMatrix, FiniteForExtremeMassesAndThinRods)
{
  Random rng(604);
  const auto bodies = hardBodies(rng);
  for (const Vector6<double>& q : hardStates(rng))
    for (const Body& b : bodies)
    {
      const Matrix6<double> M = kernelM(q, b);
      ASSERT_TRUE(M.allFinite()) << b.kind << ", q = " << q.transpose();
      for (const auto& dM : drb::massMatrixDerivatives(q, b.I))
        ASSERT_TRUE(dM.allFinite()) << b.kind << ", q = " << q.transpose();
      // Positive semi-definite, to rounding: x^T M x >= -eps |M| |x|^2.
      const Vector6<double> x = rng.vector6(1.0);
      ASSERT_GE(x.dot(M * x), -16 * kEps * maxAbs(M) * x.squaredNorm()) << b.kind << ", q = " << q.transpose();
    }
}

// massMatrixBatch: blocks of kSinCosLanes states use the vectorised sinCos,
// the tail and other scalars std::sin/cos; a block holding a non-finite or
// |angle| >= kSinCosFastLimit falls back to std::sin/cos. Each M_k must
// match the 256-bit reference to the same ulp bound as massMatrix (measured
// 4.4 ulp worst in a 200,000-state sweep for both), cos_theta must be within
// the documented absolute error of sinCos, and a bad state must not spoil
// the others in its block.
TEST(MassMatrix, BatchMatchesMpfrAndSingleStateKernel)
{
  mpreal::set_default_prec(256);
  Random rng(605);
  // cos theta: sinCos's documented absolute error (~2 ulp of 1); measured 0.7 eps.
  constexpr double kCosAbsTol = 2 * kEps;
  MaxTracker ulps, cos_err;
  const auto bodies = hardBodies(rng);
  const std::vector<double> thetas = gimbalLockThetas();
  for (const std::size_t stride : { std::size_t(6), std::size_t(9) })
    for (const std::size_t count : { std::size_t(0), std::size_t(1), std::size_t(7), std::size_t(8),
                                     std::size_t(9), std::size_t(203) })
    {
      const Body b = count == 203 ? Body{ 1.5, rng.inertia(rng.logUniform(1e-3, 1e3)), "random" }
                                  : bodies[rng.integer(0, static_cast<int>(bodies.size()) - 1)];
      std::vector<double> q(stride * count + 1, 0.0);
      for (std::size_t k = 0; k < count; ++k)
      {
        Vector6<double> qk = rng.state();
        if (k % 3 == 1)
          qk[1] = thetas[k % thetas.size()];
        if (k % 5 == 2)
          qk[0] = rng.uniform(-1.5e6, 1.5e6);  // large, still on the fast path
        if (k == 100)
          qk[1] = 2e6;  // beyond kSinCosFastLimit: this block falls back
        for (int j = 0; j < 6; ++j)
          q[stride * k + j] = qk[j];
        for (std::size_t j = 6; j < stride; ++j)
          q[stride * k + j] = std::numeric_limits<double>::quiet_NaN();  // padding is never read
      }
      std::vector<double> M(36 * count + 1, -999.0), cos_theta(count + 1, -999.0);
      drb::massMatrixBatch(q.data(), count, stride, b.mass, b.I, M.data(), cos_theta.data());
      ASSERT_EQ(M[36 * count], -999.0);
      ASSERT_EQ(cos_theta[count], -999.0);
      for (std::size_t k = 0; k < count; ++k)
      {
        const Vector6<double> qk = Eigen::Map<const Vector6<double>>(q.data() + stride * k);
        const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> Mk(M.data() + 36 * k);
        const MatrixMp6 M_ref = drb::massMatrix(VectorMp6(qk.cast<mpreal>()), mpreal(b.mass), MatrixMp3(b.I.cast<mpreal>()));
        const mpreal err =
            (Matrix3<double>(Mk.topLeftCorner<3, 3>()).cast<mpreal>() - M_ref.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff();
        const double e = err.toDouble() / ulp(angularScale(toDouble(M_ref)));
        ulps.update(e);
        ASSERT_LE(e, kMpfrUlps) << "state " << k << " of " << count << ", stride " << stride << ", q = " << qk.transpose();
        expectExactTranslationBlock(Matrix6<double>(Mk), b.mass);
        const double e_cos = std::abs(cos_theta[k] - mpfr::cos(mpreal(qk[1])).toDouble());
        cos_err.update(e_cos);
        ASSERT_LE(e_cos, kCosAbsTol) << "theta = " << qk[1];
      }
    }
  // One NaN state in a block: NaN there, correct values for its neighbours.
  std::vector<double> q(6 * 8);
  std::vector<Vector6<double>> states;
  for (int k = 0; k < 8; ++k)
  {
    states.push_back(rng.state());
    Eigen::Map<Vector6<double>>(q.data() + 6 * k) = states.back();
  }
  q[6 * 3 + 1] = std::numeric_limits<double>::quiet_NaN();
  const Body b{ 2.0, rng.inertia(), "random" };
  std::vector<double> M(36 * 8), cos_theta(8);
  drb::massMatrixBatch(q.data(), 8, 6, b.mass, b.I, M.data(), cos_theta.data());
  EXPECT_TRUE(std::isnan(cos_theta[3]));
  for (int k = 0; k < 8; ++k)
    if (k != 3)
    {
      const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> Mk(M.data() + 36 * k);
      EXPECT_LE(maxAbs(Matrix6<double>(Mk) - kernelM(states[k], b)) / angularScale(kernelM(states[k], b)),
                2 * kMpfrUlps * kEps)
          << "state " << k;
    }
  std::printf("[measured] massMatrixBatch vs 256-bit MPFR: %.3g ulp; cos theta %.3g eps absolute\n", ulps.value,
              cos_err.value / kEps);
}

// ---------------------------------------------------------------------------
// dM/dq.

TEST(MassMatrixDerivatives, MatchComplexStep)
{
  Random rng(701);
  MaxTracker err_kernel_cs, err_ref_cs;
  std::vector<std::pair<Vector6<double>, Body>> cases;
  for (int s = 0; s < kRandomStates; ++s)
    cases.push_back({ rng.state(), { rng.logUniform(1e-3, 1e3), rng.inertia(rng.logUniform(1e-6, 1e6)), "random" } });
  const auto bodies = hardBodies(rng);
  for (const Vector6<double>& q : hardStates(rng))
    cases.push_back({ q, bodies[rng.integer(0, static_cast<int>(bodies.size()) - 1)] });
  for (const auto& [q, b] : cases)
  {
    const auto dM = drb::massMatrixDerivatives(q, b.I);
    const Matrix3<Complex> I_c = b.I.cast<Complex>();
    const Complex m_c(b.mass);
    const double scale = angularScale(kernelM(q, b));
    for (int j = 0; j < 6; ++j)
    {
      // Through the kernel (the RpyTrig overload, so psi is really passed)...
      const Eigen::MatrixXd dM_kernel_cs = complexStep(
          [&](const Vector6<Complex>& qc) { return drb::massMatrix(drb::RpyTrig<Complex>(qc[0], qc[1], qc[2]), m_c, I_c); },
          q, j);
      // ... and through the independent T^T R I_b R^T T.
      const Eigen::MatrixXd dM_ref_cs =
          complexStep([&](const Vector6<Complex>& qc) { return refMassMatrix(qc, m_c, I_c); }, q, j);
      const double e_kernel = maxAbs(dM[j] - dM_kernel_cs) / scale;
      const double e_ref = maxAbs(dM[j] - dM_ref_cs) / scale;
      err_kernel_cs.update(e_kernel);
      err_ref_cs.update(e_ref);
      ASSERT_LE(e_kernel, kComplexStepTol) << "j = " << j << ", q = " << q.transpose();
      ASSERT_LE(e_ref, kComplexStepTol) << "j = " << j << ", q = " << q.transpose();
      if (j >= 2)
      {
        // psi and t: exactly zero, both from the kernel and through its complex step.
        ASSERT_EQ(maxAbs(dM[j]), 0.0) << "j = " << j;
        ASSERT_EQ(maxAbs(dM_kernel_cs), 0.0) << "j = " << j;
      }
    }
  }
  std::printf("[measured] dM vs complex step: %.3g eps (kernel), %.3g eps (T^T R I R^T T), rel. max|M_ang|\n",
              err_kernel_cs.value / kEps, err_ref_cs.value / kEps);
}

TEST(MassMatrixDerivatives, MatchCentralDifferences)
{
  Random rng(702);
  MaxTracker err;
  for (int s = 0; s < kRandomStates; ++s)
  {
    const Vector6<double> q = rng.state();
    const Body b{ rng.logUniform(1e-3, 1e3), rng.inertia(rng.logUniform(1e-6, 1e6)), "random" };
    const auto dM = drb::massMatrixDerivatives(q, b.I);
    const double scale = angularScale(kernelM(q, b));
    for (int j = 0; j < 6; ++j)
    {
      const double h = j < 3 ? kFdStep : kFdStep * std::max(1.0, std::abs(q[j]));
      Vector6<double> qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      // Differences of the independent oracle, so that the FD check does not
      // share code with the kernel.
      const Matrix6<double> dM_fd = (refMassMatrix(qp, b.mass, b.I) - refMassMatrix(qm, b.mass, b.I)) / (qp[j] - qm[j]);
      const double e = maxAbs(dM[j] - dM_fd) / scale;
      err.update(e);
      ASSERT_LE(e, kFdTol) << "j = " << j << ", q = " << q.transpose();
    }
  }
  std::printf("[measured] dM vs central differences: %.3g rel. max|M_ang|\n", err.value);
}

// ---------------------------------------------------------------------------
// Seed typo regressions (docs/derivation.md, "The seed's typos"): eq. (22)
// prints I3 for m I3, eq. (19) prints the e_Y row as
// cos th cos psi phidot + cos psi thetadot (should be cos th sin psi).

namespace
{
Matrix3<double> seedEq19T(const Vector6<double>& q)
{
  const double ct = std::cos(q[1]), st = std::sin(q[1]), cp = std::cos(q[2]), sp = std::sin(q[2]);
  Matrix3<double> T;
  T << ct * cp, -sp, 0,  //
      ct * cp, cp, 0,    // as printed: cos th cos psi in the e_Y row
      -st, 0, 1;
  return T;
}

Matrix3<double> seedEq20T(const Vector6<double>& q)
{
  const double ct = std::cos(q[1]), st = std::sin(q[1]), cp = std::cos(q[2]), sp = std::sin(q[2]);
  Matrix3<double> T;
  T << ct * cp, -sp, 0,  //
      ct * sp, cp, 0,    //
      -st, 0, 1;
  return T;
}

/// The seed's eq. (22) with T from eq. (19) or (20) and I3 (not m I3) below.
Matrix6<double> seedMassMatrix(const Vector6<double>& q, double mass, const Matrix3<double>& I_b, bool eq19,
                               bool fix_mass)
{
  const Matrix3<double> R = refRotation(q[0], q[1], q[2]);
  const Matrix3<double> T = eq19 ? seedEq19T(q) : seedEq20T(q);
  Matrix6<double> M = Matrix6<double>::Zero();
  M.topLeftCorner<3, 3>() = T.transpose() * R * I_b * R.transpose() * T;
  M.bottomRightCorner<3, 3>() = (fix_mass ? mass : 1.0) * Matrix3<double>::Identity();
  return M;
}

/// |M - sum m_i J_i^T J_i| block by block: the angular block relative to its
/// largest entry, the rest relative to the mass (blocks can differ by 1e8).
double particleMismatch(const Matrix6<double>& M, const ParticleBody& b, const Vector6<double>& q)
{
  Matrix6<double> M_particles = Matrix6<double>::Zero();
  for (std::size_t i = 0; i < b.points.size(); ++i)
  {
    const Matrix36<double> J = refJacobian(q, b.points[i]);
    M_particles += b.masses[i] * J.transpose() * J;
  }
  Matrix6<double> diff = M - M_particles;
  const double angular = maxAbs(diff.topLeftCorner<3, 3>()) / angularScale(M_particles);
  diff.topLeftCorner<3, 3>().setZero();
  return std::max(angular, maxAbs(diff) / b.mass);
}
}  // namespace

TEST(SeedTypos, Eq22UnitMassBlockFailsParticleIdentityAndOursPasses)
{
  Random rng(801);
  int caught = 0, total = 0;
  for (int s = 0; s < 50; ++s)
  {
    const ParticleBody b = particleBody(rng, false);
    if (std::abs(b.mass - 1.0) < 0.1)
      continue;  // a unit mass hides the typo
    const Vector6<double> q = rng.state();
    ++total;
    const double seed = particleMismatch(seedMassMatrix(q, b.mass, b.inertia, false, false), b, q);
    const double seed_fixed = particleMismatch(seedMassMatrix(q, b.mass, b.inertia, false, true), b, q);
    const double ours = particleMismatch(drb::massMatrix(q, b.mass, b.inertia), b, q);
    if (seed > 1e-3)
      ++caught;
    EXPECT_LE(seed_fixed, kParticleTol) << "eq. (20) with m I3 is right";
    EXPECT_LE(ours, kParticleTol);
    // And the kinetic energy of a pure translation: 1/2 m |v|^2.
    Vector6<double> qdot = Vector6<double>::Zero();
    qdot.tail<3>() = rng.vector(1.0);
    const double expected = 0.5 * b.mass * qdot.tail<3>().squaredNorm();
    EXPECT_NEAR(0.5 * qdot.dot(drb::massMatrix(q, b.mass, b.inertia) * qdot), expected, 4 * kEps * expected);
  }
  ASSERT_GT(total, 30);
  EXPECT_EQ(caught, total) << "the particle identity must reject eq. (22)'s I3 whenever m != 1";
  std::printf("[measured] seed eq. (22) rejected at %d/%d bodies\n", caught, total);
}

TEST(SeedTypos, Eq19RowFailsAngularVelocityAndParticleIdentityAndOursPasses)
{
  Random rng(802);
  int caught_omega = 0, caught_M = 0, total = 0;
  for (int s = 0; s < 50; ++s)
  {
    const Vector6<double> q = rng.state();
    // The e_Y rows differ by cos th (cos psi - sin psi) phidot.
    if (std::abs(std::cos(q[1]) * (std::cos(q[2]) - std::sin(q[2]))) < 0.05)
      continue;
    ++total;
    const Eigen::Vector3d rdot = rng.vector(1.0) + Eigen::Vector3d(1.0, 0, 0);  // phidot != 0
    // omega from the rotation itself: [omega]_x = Rdot R^T, Rdot by the complex step.
    const Matrix3<Complex> Rc = refRotation(Complex(q[0], kComplexStepH * rdot[0]), Complex(q[1], kComplexStepH * rdot[1]),
                                            Complex(q[2], kComplexStepH * rdot[2]));
    const Eigen::Vector3d omega = vee(Matrix3<double>(Rc.imag() / kComplexStepH * refRotation(q[0], q[1], q[2]).transpose()));
    if ((seedEq19T(q) * rdot - omega).norm() > 1e-3 * rdot.norm())
      ++caught_omega;
    EXPECT_LE((seedEq20T(q) * rdot - omega).norm(), 1e-14 * rdot.norm());
    EXPECT_LE((drb::angularVelocityMatrixWorld(drb::RpyTrig<double>(q[0], q[1], q[2])) * rdot - omega).norm(),
              1e-14 * rdot.norm());

    const ParticleBody b = particleBody(rng, false);
    if (particleMismatch(seedMassMatrix(q, b.mass, b.inertia, true, true), b, q) > 1e-6)
      ++caught_M;
  }
  ASSERT_GT(total, 30);
  EXPECT_EQ(caught_omega, total);
  EXPECT_EQ(caught_M, total);
  std::printf("[measured] seed eq. (19) rejected at %d/%d (omega) and %d/%d (particle identity) states\n",
              caught_omega, total, caught_M, total);
}

// ---------------------------------------------------------------------------

TEST(MassMatrix, FloatAgreesWithDouble)
{
  Random rng(901);
  MaxTracker err;
  for (int s = 0; s < kRandomStates; ++s)
  {
    const Vector6<float> qf = rng.state().cast<float>();
    const Matrix3<float> If = rng.inertia(rng.logUniform(1e-3, 1e3)).cast<float>();
    const float mf = static_cast<float>(rng.logUniform(1e-3, 1e3));
    const Vector6<double> q = qf.cast<double>();
    const Matrix3<double> I = If.cast<double>();
    const double m = mf;
    const Matrix6<double> M = drb::massMatrix(q, m, I);
    const double scale = angularScale(M);
    double e = maxAbs(drb::massMatrix(qf, mf, If).cast<double>() - M) / scale;
    const auto dMf = drb::massMatrixDerivatives(qf, If);
    const auto dM = drb::massMatrixDerivatives(q, I);
    for (int j = 0; j < 6; ++j)
      e = std::max(e, maxAbs(dMf[j].cast<double>() - dM[j]) / scale);
    err.update(e);
    ASSERT_LE(e, kFloatTol) << "q = " << q.transpose();
  }
  std::printf("[measured] float vs double (M, dM): %.3g float eps\n", err.value / FLT_EPSILON);
}
