// Oracle tests for vertex_jacobian.h: p = R p0 + t, J = dp/dq and the
// vector-Jacobian product (backprop).
//
// Oracles:
//   - the complex step through the templated vertexPosition<std::complex<double>>
//     (h = 1e-30, derivative = Im(p(q + i h e_j))/h, no cancellation);
//   - central differences of vertexPosition<double>;
//   - the long form dp/dr_k = (dR/dr_k) p0 with dR from elementary rotations
//     (oracles.h), independent of the kernel's cross-product form;
//   - for backprop: sum_i J_i^T g_i with the long-form J, and the complex step
//     of the scalar loss L(q) = sum_i g_i . p_i(q).
//
// Error measure for J: the rotation block (dp/dr, 3x3) is compared relative
// to |p0| (= |R p0|, the lever arm). Each entry of the block is bounded by
// |p0| (unit axis x lever arm) and, because the Y' and Z axes are orthonormal,
// the block's Frobenius norm is >= |p0|, so the largest entry is >= |p0|/sqrt(6):
// "relative to |p0|" is "relative to the largest entry" within a factor 2.5.
// The translation block must be exactly I3.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "diff_rigid_body/algorithm/free_body/vertex_columns.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"
#include "reference/vertex_kernels.h"
#include "../support/oracles.h"

namespace drb = diff_rigid_body;
using namespace drb_test;

namespace
{
// Complex step: the bound, 1e-14 relative to |p0| (~45 ulp); the
// kernel's and the complex evaluation's roundings are a few ulp each.
constexpr double kComplexStepTol = 1e-14;
// Long-form oracle in double: both sides within a few ulp of |p0|.
constexpr double kLongFormTol = 16 * kEps;
// Central differences with step h [rad] on the angles: truncation
// <= h^2/6 |p0| (each angle rotates p about a fixed unit axis, so
// |d^3p/dr^3| <= |p0|) and rounding <= ~eps |p| / h with |p| <= |p0| + |t|.
// We allow 6x the truncation bound and 8x the rounding estimate.
constexpr double kFdStep = 1e-5;  // [rad], and [m] per unit of max(1, |t_j|)
double fdTolerance(const Vector3<double>& p0, const Vector6<double>& q)
{
  return kFdStep * kFdStep * p0.norm() + 8 * kEps * (p0.norm() + q.tail<3>().norm()) / kFdStep;
}
// Positions: R p0 is within a few ulp of |p0|, adding t rounds once more.
constexpr double kPositionTol = 8 * kEps;  // relative to |p0| + |t|
// Large angles vs the exactly wrapped angle (rounded to double: <= 0.5 ulp(pi)
// = 2.2e-16 rad, moving p by <= 2.2e-16 |p0|) plus the kernel's few ulp on
// each side; relative to |p0|.
constexpr double kWrappedTol = 16 * kEps;
// Backprop: sums over N vertices. Relative to S = sum_i |p0_i| |g_i| (the
// rotation part) and sum_i |g_i| (translation); rounding grows ~ N eps in the
// worst case; with random signs we measure ~1 eps and allow 16 eps.
constexpr double kBackpropTol = 16 * kEps;
// Float kernels vs double at the same float inputs, relative to |p0|.
constexpr double kFloatTol = 16 * FLT_EPSILON;

constexpr int kRandomStates = 1000;

Matrix36<double> kernelJ(const Vector6<double>& q, const Vector3<double>& p0)
{
  return drb::vertexJacobian(drb::BodyPose<double>(q), p0);
}

Vector3<double> kernelP(const Vector6<double>& q, const Vector3<double>& p0)
{
  return drb::vertexPosition(drb::BodyPose<double>(q), p0);
}

/// J by the complex step through vertexPosition<std::complex<double>>.
Matrix36<double> complexStepJ(const Vector6<double>& q, const Vector3<double>& p0)
{
  Matrix36<double> J;
  const Vector3<Complex> p0c = p0.cast<Complex>();
  for (int j = 0; j < 6; ++j)
    J.col(j) = complexStep(
        [&](const Vector6<Complex>& qc) { return drb::vertexPosition(drb::BodyPose<Complex>(qc), p0c); }, q, j);
  return J;
}

/// J by central differences of vertexPosition<double>.
Matrix36<double> centralDifferenceJ(const Vector6<double>& q, const Vector3<double>& p0,
                                    Vector3<double> (*position)(const Vector6<double>&, const Vector3<double>&) = kernelP)
{
  Matrix36<double> J;
  for (int j = 0; j < 6; ++j)
  {
    const double h = j < 3 ? kFdStep : kFdStep * std::max(1.0, std::abs(q[j]));
    Vector6<double> qp = q, qm = q;
    qp[j] += h;
    qm[j] -= h;
    J.col(j) = (position(qp, p0) - position(qm, p0)) / (qp[j] - qm[j]);
  }
  return J;
}

double rotationBlockError(const Matrix36<double>& J, const Matrix36<double>& J_ref, const Vector3<double>& p0)
{
  return maxAbs(J.leftCols<3>() - J_ref.leftCols<3>()) / p0.norm();
}

struct Case
{
  Vector6<double> q;
  Vector3<double> p0;
};

std::vector<Case> randomCases(std::uint64_t seed)
{
  Random rng(seed);
  std::vector<Case> cases;
  for (int i = 0; i < kRandomStates; ++i)
  {
    const Vector6<double> q = rng.state();
    cases.push_back({ q, rng.vector(1.0) });
    cases.push_back({ q, rng.vertexOfNorm(rng.logUniform(1e-6, 1e4)) });
  }
  return cases;
}

/// Gimbal lock (every theta of the list, several phi/psi) x vertex scales
/// (1e-6 m .. 1e4 m). Tiny bodies sit near the origin (t ~ scale) so that
/// their derivatives are not swamped by |t| in the differences.
std::vector<Case> gimbalCases(std::uint64_t seed)
{
  Random rng(seed);
  std::vector<Case> cases;
  for (const double theta : gimbalLockThetas())
    for (const double scale : vertexScales())
      for (int n = 0; n < 3; ++n)
      {
        Vector6<double> q = rng.state();
        q[1] = theta;
        q.tail<3>() = rng.vector(std::min(10.0, 10 * scale));
        cases.push_back({ q, rng.vertexOfNorm(scale) });
      }
  // phi and psi at exact multiples of pi/2 too.
  for (const double theta : { kHalfPi, -kHalfPi })
    for (int a = -2; a <= 2; ++a)
    {
      Vector6<double> q = Vector6<double>::Zero();
      q << a * kHalfPi, theta, -a * kHalfPi, 1, 2, 3;
      cases.push_back({ q, Vector3<double>(0.3, -0.7, 1.1) });
    }
  return cases;
}

void checkAgainstOracles(const std::vector<Case>& cases, const char* label)
{
  MaxTracker err_cs, err_long, err_fd_ratio;
  for (const Case& c : cases)
  {
    const Matrix36<double> J = kernelJ(c.q, c.p0);
    ASSERT_TRUE(J.allFinite());
    // Translation block: exactly I3, and the complex step gives exactly 1/0.
    const Matrix36<double> J_cs = complexStepJ(c.q, c.p0);
    ASSERT_EQ(maxAbs(J.rightCols<3>() - Eigen::Matrix3d::Identity()), 0.0);
    ASSERT_EQ(maxAbs(J_cs.rightCols<3>() - Eigen::Matrix3d::Identity()), 0.0);

    const double e_cs = rotationBlockError(J, J_cs, c.p0);
    const double e_long = rotationBlockError(J, refJacobian(c.q, c.p0), c.p0);
    const double e_fd = maxAbs(J - centralDifferenceJ(c.q, c.p0));
    const double fd_tol = fdTolerance(c.p0, c.q);
    err_cs.update(e_cs);
    err_long.update(e_long);
    err_fd_ratio.update(e_fd / fd_tol);
    ASSERT_LE(e_cs, kComplexStepTol) << label << ": q = " << c.q.transpose() << ", p0 = " << c.p0.transpose();
    ASSERT_LE(e_long, kLongFormTol) << label << ": q = " << c.q.transpose() << ", p0 = " << c.p0.transpose();
    ASSERT_LE(e_fd, fd_tol) << label << ": q = " << c.q.transpose() << ", p0 = " << c.p0.transpose();
  }
  std::printf("[measured] %s (%zu cases): J vs complex step %.3g eps rel |p0|; vs long form %.3g eps; "
              "central diff at %.2g of its tolerance\n",
              label, cases.size(), err_cs.value / kEps, err_long.value / kEps, err_fd_ratio.value);
}

/// The seed's section C as printed, including the missing parentheses in
/// dx/dphi: p_y sin phi sin psi + cos phi sin th cos psi + p_z (...).
Matrix36<double> seedJacobianAsPrinted(const Vector6<double>& q, const Vector3<double>& p, bool fix_dx_dphi)
{
  const double sf = std::sin(q[0]), cf = std::cos(q[0]);
  const double st = std::sin(q[1]), ct = std::cos(q[1]);
  const double ss = std::sin(q[2]), cs = std::cos(q[2]);
  const double px = p[0], py = p[1], pz = p[2];
  Matrix36<double> J = Matrix36<double>::Zero();
  J.rightCols<3>().setIdentity();
  // dx/dpsi, dx/dtheta, dx/dphi
  J(0, 2) = -px * ct * ss + py * (-cf * cs - sf * st * ss) + pz * (sf * cs - cf * st * ss);
  J(0, 1) = -px * st * cs + py * sf * ct * cs + pz * cf * ct * cs;
  J(0, 0) = fix_dx_dphi ? py * (sf * ss + cf * st * cs) + pz * (cf * ss - sf * st * cs)
                        : py * sf * ss + cf * st * cs + pz * (cf * ss - sf * st * cs);  // as printed
  // dy/dpsi, dy/dtheta, dy/dphi
  J(1, 2) = px * ct * cs + py * (-cf * ss + sf * st * cs) + pz * (sf * ss + cf * st * cs);
  J(1, 1) = -px * st * ss + py * sf * ct * ss + pz * cf * ct * ss;
  J(1, 0) = py * (-sf * cs + cf * st * ss) + pz * (-cf * cs - sf * st * ss);
  // dz/dpsi, dz/dtheta, dz/dphi
  J(2, 2) = 0;
  J(2, 1) = -px * ct - py * sf * st - pz * cf * st;
  J(2, 0) = py * cf * ct - pz * sf * ct;
  return J;
}

std::vector<double> randomGradients(Random& rng, std::size_t count)
{
  std::vector<double> g(3 * count);
  for (double& x : g)
    x = rng.uniform(-1.0, 1.0);
  return g;
}

struct BackpropCheck
{
  double rotation_error;     // relative to sum |p0_i| |g_i|
  double translation_error;  // relative to sum |g_i|
  double loss_cs_error;      // complex step of L, relative as above
};

/// Checks backpropagateVertexGradients(indices) against sum_i J_i^T g_i with
/// the long-form J and against the complex step of L = sum_i g_i . p_i(q).
/// With no indices the by-coordinate kernel (vertex_columns.h) is checked
/// too, and the worst of the two kernels is returned.
BackpropCheck checkBackprop(const Vector6<double>& q, const drb::Matrix3X<double>& vertices,
                            const std::vector<std::uint32_t>& indices, const std::vector<double>& g)
{
  const std::size_t count = indices.empty() ? static_cast<std::size_t>(vertices.cols()) : indices.size();
  EXPECT_EQ(g.size(), 3 * count);
  const drb::BodyPose<double> pose(q);
  std::vector<Vector6<double>> answers = { drb::backpropagateVertexGradients(pose, vertices, indices, g.data()) };
  if (indices.empty())
    answers.push_back(drb::backpropagateVertexGradients(pose, drb::VertexColumns<double>(vertices.transpose()),
                                                        g.data()));

  Vector6<double> expected = Vector6<double>::Zero();
  double torque_scale = 0, force_scale = 0;
  Complex loss_at[6] = {};
  Vector6<Complex> qc[6];
  for (int j = 0; j < 6; ++j)
    qc[j] = complexPerturbed(q, j);
  for (std::size_t n = 0; n < count; ++n)
  {
    const Eigen::Index v = indices.empty() ? static_cast<Eigen::Index>(n) : indices[n];
    const Vector3<double> p0 = vertices.col(v);
    const Vector3<double> gi(g[3 * n], g[3 * n + 1], g[3 * n + 2]);
    expected += refJacobian(q, p0).transpose() * gi;
    torque_scale += p0.norm() * gi.norm();
    force_scale += gi.norm();
    for (int j = 0; j < 6; ++j)
      // (Not .dot(): Eigen's dot conjugates its left operand.)
      loss_at[j] += refPosition(qc[j], Vector3<Complex>(p0.cast<Complex>())).cwiseProduct(gi.cast<Complex>()).sum();
  }
  Vector6<double> dL_cs;
  for (int j = 0; j < 6; ++j)
    dL_cs[j] = loss_at[j].imag() / kComplexStepH;
  BackpropCheck worst{ 0, 0, 0 };
  for (const Vector6<double>& dL : answers)
  {
    EXPECT_TRUE(dL.allFinite());
    worst.rotation_error = std::max(worst.rotation_error, maxAbs(dL.head<3>() - expected.head<3>()) / torque_scale);
    worst.translation_error =
        std::max(worst.translation_error, maxAbs(dL.tail<3>() - expected.tail<3>()) / force_scale);
    worst.loss_cs_error = std::max({ worst.loss_cs_error, maxAbs(dL.head<3>() - dL_cs.head<3>()) / torque_scale,
                                     maxAbs(dL.tail<3>() - dL_cs.tail<3>()) / force_scale });
  }
  return worst;
}

drb::Matrix3X<double> randomVertices(Random& rng, int count, double scale)
{
  drb::Matrix3X<double> v(3, count);
  for (int i = 0; i < count; ++i)
    v.col(i) = rng.vector(scale);
  return v;
}
}  // namespace

// ---------------------------------------------------------------------------

TEST(VertexJacobian, PositionMatchesProductForm)
{
  MaxTracker err;
  for (const auto& cases : { randomCases(201), gimbalCases(202) })
    for (const Case& c : cases)
    {
      const double scale = c.p0.norm() + c.q.tail<3>().norm();
      const double e = maxAbs(kernelP(c.q, c.p0) - refPosition(c.q, c.p0)) / scale;
      err.update(e);
      ASSERT_LE(e, kPositionTol) << "q = " << c.q.transpose() << ", p0 = " << c.p0.transpose();
    }
  std::printf("[measured] |p - (Rz Ry Rx p0 + t)| = %.3g eps rel (|p0| + |t|)\n", err.value / kEps);
}

TEST(VertexJacobian, MatchesOraclesAtRandomStates)
{
  checkAgainstOracles(randomCases(203), "random states");
}

TEST(VertexJacobian, MatchesOraclesAtGimbalLock)
{
  checkAgainstOracles(gimbalCases(204), "gimbal lock x vertex scales");
}

// Angles up to 1e6 rad: J agrees with the complex step there, and with J at
// the exactly wrapped angle within the argument-reduction error.
TEST(VertexJacobian, LargeAnglesMatchComplexStepAndWrappedAngle)
{
  Random rng(205);
  std::vector<Case> cases;
  const auto angles = largeAngles();
  const int last = static_cast<int>(angles.size()) - 1;
  for (const double a : angles)
    for (const double scale : vertexScales())
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        Vector6<double> q = rng.state();
        q[axis] = a;
        q.tail<3>() = rng.vector(std::min(10.0, 10 * scale));
        cases.push_back({ q, rng.vertexOfNorm(scale) });
      }
      // All three angles large at once.
      Vector6<double> q;
      q << a, angles[rng.integer(0, last)], angles[rng.integer(0, last)],
          rng.vector(std::min(10.0, 10 * scale));
      cases.push_back({ q, rng.vertexOfNorm(scale) });
    }
  checkAgainstOracles(cases, "angles up to 1e6 rad");

  MaxTracker err;
  for (const Case& c : cases)
  {
    Vector6<double> q_wrapped = c.q;
    for (int k = 0; k < 3; ++k)
      q_wrapped[k] = wrapAngleExact(c.q[k]);
    const double e_J = rotationBlockError(kernelJ(c.q, c.p0), kernelJ(q_wrapped, c.p0), c.p0);
    const double e_p = maxAbs(kernelP(c.q, c.p0) - kernelP(q_wrapped, c.p0)) / (c.p0.norm() + c.q.tail<3>().norm());
    err.update(std::max(e_J, e_p));
    ASSERT_LE(e_J, kWrappedTol) << "q = " << c.q.transpose();
    ASSERT_LE(e_p, kWrappedTol) << "q = " << c.q.transpose();
  }
  std::printf("[measured] large angles vs exact wrap: %.3g eps\n", err.value / kEps);
}

// The batch kernel writes row-major 3x6 blocks and the positions, for all
// vertices or for an index list (with repeats), and skips null outputs.
TEST(VertexJacobian, BatchLayoutMatchesOracle)
{
  Random rng(206);
  const Vector6<double> q = rng.state();
  const drb::Matrix3X<double> vertices = randomVertices(rng, 20, 2.0);
  const drb::BodyPose<double> pose(q);
  for (const std::vector<std::uint32_t>& indices :
       { std::vector<std::uint32_t>{}, std::vector<std::uint32_t>{ 7, 0, 7, 19, 3, 3, 3, 12 } })
  {
    const std::size_t count = indices.empty() ? 20 : indices.size();
    std::vector<double> positions(3 * count, -999.0), jacobians(18 * count, -999.0);
    drb::vertexPositionsAndJacobians(pose, vertices, indices, positions.data(), jacobians.data());
    for (std::size_t n = 0; n < count; ++n)
    {
      const Vector3<double> p0 = vertices.col(indices.empty() ? n : indices[n]);
      const Matrix36<double> J_ref = refJacobian(q, p0);
      const Vector3<double> p_ref = refPosition(q, p0);
      for (int i = 0; i < 3; ++i)
      {
        EXPECT_NEAR(positions[3 * n + i], p_ref[i], kPositionTol * (p0.norm() + q.tail<3>().norm()))
            << "vertex " << n << " row " << i;
        for (int j = 0; j < 6; ++j)
          EXPECT_NEAR(jacobians[18 * n + 6 * i + j], J_ref(i, j), kLongFormTol * p0.norm())
              << "vertex " << n << " entry (" << i << "," << j << ")";
      }
    }
    // Null outputs are skipped; the other output is unchanged.
    std::vector<double> only_positions(3 * count, -999.0), only_jacobians(18 * count, -999.0);
    drb::vertexPositionsAndJacobians(pose, vertices, indices, only_positions.data(), static_cast<double*>(nullptr));
    drb::vertexPositionsAndJacobians(pose, vertices, indices, static_cast<double*>(nullptr), only_jacobians.data());
    EXPECT_EQ(only_positions, positions);
    EXPECT_EQ(only_jacobians, jacobians);
  }
}

// The double batch kernel has SIMD paths: pairs of vertices (adjacent
// vertices loaded together, others lane by lane), an odd last vertex, and
// streaming stores for outputs >= kStreamingStoreBytes into 16-byte aligned
// buffers. Every count, selection shape and alignment must give the oracle's
// values and, as documented, the same bits as the single-vertex kernels.
namespace
{
/// Checks `count` outputs of the batch kernel against vertexJacobian /
/// vertexPosition (bits, or 4 eps where FMA contraction may differ) and, for
/// every `oracle_every`-th vertex, against the long-form oracle.
void expectBatchMatches(const Vector6<double>& q, const drb::Matrix3X<double>& vertices,
                        const std::vector<std::uint32_t>& indices, const double* positions, const double* jacobians,
                        std::size_t oracle_every = 1)
{
  const drb::BodyPose<double> pose(q);
  const std::size_t count = indices.empty() ? static_cast<std::size_t>(vertices.cols()) : indices.size();
#if defined(__FMA__)
  const double same_tol = 4 * kEps;  // contraction may round differently per path
#else
  const double same_tol = 0.0;  // documented: the same bits on every path
#endif
  for (std::size_t n = 0; n < count; ++n)
  {
    const Vector3<double> p0 = vertices.col(indices.empty() ? n : indices[n]);
    const Matrix36<double> J = drb::vertexJacobian(pose, p0);
    const Vector3<double> p = drb::vertexPosition(pose, p0);
    const double scale = std::max(p0.norm(), 1.0);
    for (int i = 0; i < 3; ++i)
    {
      if (positions)
      {
        ASSERT_LE(std::abs(positions[3 * n + i] - p[i]), same_tol * (p0.norm() + q.tail<3>().norm()))
            << "vertex " << n << " of " << count << ", row " << i;
      }
      for (int j = 0; j < 6; ++j)
        ASSERT_LE(std::abs(jacobians[18 * n + 6 * i + j] - J(i, j)), same_tol * scale)
            << "vertex " << n << " of " << count << ", entry (" << i << "," << j << ")";
    }
    if (n % oracle_every == 0)
    {
      const Matrix36<double> J_ref = refJacobian(q, p0);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 6; ++j)
          ASSERT_LE(std::abs(jacobians[18 * n + 6 * i + j] - J_ref(i, j)), kLongFormTol * scale)
              << "vertex " << n << " entry (" << i << "," << j << ")";
    }
  }
}
}  // namespace

TEST(VertexJacobian, BatchEveryCountSelectionAndAlignment)
{
  Random rng(207);
  const Vector6<double> q = rng.state();
  const drb::BodyPose<double> pose(q);
  const drb::Matrix3X<double> pool = randomVertices(rng, 40, 3.0);
  std::vector<std::pair<drb::Matrix3X<double>, std::vector<std::uint32_t>>> cases;
  for (int count = 0; count <= 11; ++count)
    cases.push_back({ drb::Matrix3X<double>(pool.leftCols(count)), {} });  // all, even and odd counts
  for (const std::vector<std::uint32_t>& indices :
       { std::vector<std::uint32_t>{ 4 }, { 4, 5 }, { 4, 5, 6 }, { 9, 8, 7, 6, 5 }, { 3, 3 }, { 3, 3, 3 },
         { 0, 39, 1, 38, 2, 37, 20 }, { 39, 39, 0, 1, 2, 3, 10, 11 } })
    cases.push_back({ pool, indices });
  for (const auto& [vertices, indices] : cases)
  {
    const std::size_t count = indices.empty() ? static_cast<std::size_t>(vertices.cols()) : indices.size();
    for (const std::size_t offset : { 0, 1 })  // 16-byte aligned, and not
      for (const bool with_positions : { true, false })
      {
        std::vector<double> P(3 * count + 2, -999.0), J(18 * count + 2, -999.0);
        double* positions = with_positions ? P.data() + offset : nullptr;
        drb::vertexPositionsAndJacobians(pose, vertices, indices, positions, J.data() + offset);
        expectBatchMatches(q, vertices, indices, positions, J.data() + offset);
        // Nothing written outside the outputs.
        ASSERT_EQ(J[offset ? 0 : 18 * count], -999.0);
        ASSERT_EQ(J[18 * count + 1], -999.0);
        ASSERT_EQ(P[3 * count + 1], -999.0);
        if (!with_positions)
        {
          ASSERT_EQ(P[offset], -999.0);
        }
      }
    // Positions only.
    std::vector<double> P(3 * count);
    drb::vertexPositionsAndJacobians(pose, vertices, indices, P.data(), static_cast<double*>(nullptr));
    for (std::size_t n = 0; n < count; ++n)
    {
      const Vector3<double> p0 = vertices.col(indices.empty() ? n : indices[n]);
      for (int i = 0; i < 3; ++i)
        ASSERT_NEAR(P[3 * n + i], refPosition(q, p0)[i], kPositionTol * (p0.norm() + q.tail<3>().norm()));
    }
  }
}

TEST(VertexJacobian, BatchStreamingPathForLargeOutputs)
{
  Random rng(208);
  const Vector6<double> q = rng.state();
  // Just past the streaming threshold, an odd count that is not a multiple
  // of the 16-vertex streaming block.
  const std::size_t count = drb::kStreamingStoreBytes / (18 * sizeof(double)) + 37;
  drb::Matrix3X<double> vertices(3, static_cast<Eigen::Index>(count));
  for (Eigen::Index i = 0; i < vertices.cols(); ++i)
    vertices.col(i) = rng.vector(2.0);
  std::vector<double> P(3 * count), J(18 * count);
  ASSERT_EQ(reinterpret_cast<std::uintptr_t>(J.data()) % 16, 0u);
  ASSERT_EQ(reinterpret_cast<std::uintptr_t>(P.data()) % 16, 0u);
  drb::vertexPositionsAndJacobians(drb::BodyPose<double>(q), vertices, {}, P.data(), J.data());
  expectBatchMatches(q, vertices, {}, P.data(), J.data(), 97);
  // Without positions, and through an index list.
  std::vector<std::uint32_t> indices(count);
  for (std::size_t n = 0; n < count; ++n)
    indices[n] = static_cast<std::uint32_t>((n * 7919) % count);
  std::fill(J.begin(), J.end(), -999.0);
  drb::vertexPositionsAndJacobians(drb::BodyPose<double>(q), vertices, indices, static_cast<double*>(nullptr),
                                   J.data());
  expectBatchMatches(q, vertices, indices, nullptr, J.data(), 97);
}

// The reduced transport writes only the rotation block (3x3 row-major per
// vertex), equal to the full kernel's before the conversion to Out.
TEST(VertexJacobian, RotationJacobiansMatchFullKernel)
{
  Random rng(209);
  for (int s = 0; s < 20; ++s)
  {
    const Vector6<double> q = rng.state();
    const drb::BodyPose<double> pose(q);
    const drb::Matrix3X<double> vertices = randomVertices(rng, 13, rng.logUniform(1e-6, 1e4));
    for (const std::vector<std::uint32_t>& indices : { std::vector<std::uint32_t>{}, { 12, 0, 5, 5 } })
    {
      const std::size_t count = indices.empty() ? 13 : indices.size();
      std::vector<double> P(3 * count), J(18 * count), Pd(3 * count), Jd(9 * count);
      std::vector<float> Pf(3 * count), Jf(9 * count);
      drb::vertexPositionsAndJacobians(pose, vertices, indices, P.data(), J.data());
      drb::vertexPositionsAndRotationJacobians(pose, vertices, indices, Pd.data(), Jd.data());
      drb::vertexPositionsAndRotationJacobians(pose, vertices, indices, Pf.data(), Jf.data());
      for (std::size_t n = 0; n < count; ++n)
        for (int i = 0; i < 3; ++i)
        {
          ASSERT_EQ(Pd[3 * n + i], P[3 * n + i]);
          ASSERT_EQ(Pf[3 * n + i], static_cast<float>(P[3 * n + i]));
          for (int k = 0; k < 3; ++k)
          {
            ASSERT_EQ(Jd[9 * n + 3 * i + k], J[18 * n + 6 * i + k]) << "vertex " << n;
            ASSERT_EQ(Jf[9 * n + 3 * i + k], static_cast<float>(J[18 * n + 6 * i + k])) << "vertex " << n;
          }
        }
    }
  }
}

// ---------------------------------------------------------------------------
// Backprop.

TEST(Backprop, AllVerticesMatchesJTransposeGAndComplexStep)
{
  Random rng(301);
  MaxTracker err_rot, err_trans, err_cs;
  for (int s = 0; s < 200; ++s)
  {
    const Vector6<double> q = rng.state();
    const drb::Matrix3X<double> vertices = randomVertices(rng, 64, rng.logUniform(1e-3, 1e3));
    const BackpropCheck r = checkBackprop(q, vertices, {}, randomGradients(rng, 64));
    err_rot.update(r.rotation_error);
    err_trans.update(r.translation_error);
    err_cs.update(r.loss_cs_error);
    ASSERT_LE(r.rotation_error, kBackpropTol) << "q = " << q.transpose();
    ASSERT_LE(r.translation_error, kBackpropTol) << "q = " << q.transpose();
    ASSERT_LE(r.loss_cs_error, kBackpropTol) << "q = " << q.transpose();
  }
  std::printf("[measured] backprop (all 64 vertices): rotation %.3g eps, translation %.3g eps, "
              "vs complex step of L %.3g eps\n",
              err_rot.value / kEps, err_trans.value / kEps, err_cs.value / kEps);
}

TEST(Backprop, IndexSubsetWithRepeats)
{
  Random rng(302);
  const std::vector<std::uint32_t> indices = { 5, 0, 5, 63, 17, 17, 17, 2, 40, 5 };
  MaxTracker err;
  for (int s = 0; s < 200; ++s)
  {
    const Vector6<double> q = rng.state();
    const drb::Matrix3X<double> vertices = randomVertices(rng, 64, 1.0);
    const BackpropCheck r = checkBackprop(q, vertices, indices, randomGradients(rng, indices.size()));
    err.update(std::max({ r.rotation_error, r.translation_error, r.loss_cs_error }));
    ASSERT_LE(r.rotation_error, kBackpropTol) << "q = " << q.transpose();
    ASSERT_LE(r.translation_error, kBackpropTol) << "q = " << q.transpose();
    ASSERT_LE(r.loss_cs_error, kBackpropTol) << "q = " << q.transpose();
  }
  // A subset is not the same as all vertices: the gradient of vertex 5
  // counts three times.
  const Vector6<double> q = rng.state();
  const drb::Matrix3X<double> vertices = randomVertices(rng, 64, 1.0);
  const std::vector<double> g = randomGradients(rng, indices.size());
  std::vector<double> g_all(3 * 64, 0.0);
  for (std::size_t n = 0; n < indices.size(); ++n)
    for (int i = 0; i < 3; ++i)
      g_all[3 * indices[n] + i] += g[3 * n + i];
  const drb::BodyPose<double> pose(q);
  const Vector6<double> subset = drb::backpropagateVertexGradients(pose, vertices, indices, g.data());
  const Vector6<double> scattered = drb::backpropagateVertexGradients(pose, vertices, {}, g_all.data());
  EXPECT_LE(maxAbs(subset - scattered), 1e-14 * (1 + maxAbs(scattered)));
  std::printf("[measured] backprop (subset with repeats): %.3g eps\n", err.value / kEps);
}

TEST(Backprop, HardCases)
{
  Random rng(303);
  MaxTracker err;
  std::vector<Vector6<double>> states = gimbalLockStates(rng);
  for (const double a : largeAngles())
  {
    Vector6<double> q = rng.state();
    q[rng.integer(0, 2)] = a;
    states.push_back(q);
  }
  for (const Vector6<double>& q : states)
    for (const double scale : vertexScales())
    {
      const drb::Matrix3X<double> vertices = randomVertices(rng, 16, scale);
      const BackpropCheck r = checkBackprop(q, vertices, { 3, 3, 0, 15 }, randomGradients(rng, 4));
      const double e = std::max({ r.rotation_error, r.translation_error, r.loss_cs_error });
      err.update(e);
      ASSERT_LE(e, kBackpropTol) << "q = " << q.transpose() << ", scale " << scale;
    }
  std::printf("[measured] backprop hard cases: %.3g eps\n", err.value / kEps);
}

// The double backprop sums 2, 4 or 8 vertices per SIMD register and the rest
// one by one: every count and selection length must match J^T g.
TEST(Backprop, EveryCountAndSelectionLength)
{
  Random rng(304);
  MaxTracker err;
  for (int count = 1; count <= 33; ++count)
    for (int rep = 0; rep < 5; ++rep)
    {
      const Vector6<double> q = rng.state();
      const drb::Matrix3X<double> vertices = randomVertices(rng, count, rng.logUniform(1e-3, 1e3));
      const BackpropCheck all = checkBackprop(q, vertices, {}, randomGradients(rng, count));
      std::vector<std::uint32_t> indices(static_cast<std::size_t>(rng.integer(1, 9)));
      for (auto& index : indices)
        index = static_cast<std::uint32_t>(rng.integer(0, count - 1));
      const BackpropCheck subset = checkBackprop(q, vertices, indices, randomGradients(rng, indices.size()));
      for (const BackpropCheck& r : { all, subset })
      {
        const double e = std::max({ r.rotation_error, r.translation_error, r.loss_cs_error });
        err.update(e);
        ASSERT_LE(e, kBackpropTol) << count << " vertices, q = " << q.transpose();
      }
    }
  std::printf("[measured] backprop, 1..33 vertices and subsets: %.3g eps\n", err.value / kEps);
}

TEST(Backprop, EmptySelectionGivesZero)
{
  const drb::Matrix3X<double> none(3, 0);
  const drb::BodyPose<double> pose(Vector6<double>::Ones());
  EXPECT_EQ(drb::backpropagateVertexGradients(pose, none, {}, static_cast<const double*>(nullptr)),
            Vector6<double>::Zero());
  EXPECT_EQ(drb::backpropagateVertexGradients(pose, drb::VertexColumns<double>(0, 3), nullptr, 4),
            Vector6<double>::Zero());
}

// Large meshes split over threads: every thread count agrees with sum_i
// J_i^T g_i accumulated in long double with the long-form J, and a given
// thread count always returns the same bits (chunks are added in order).
TEST(Backprop, ThreadsMatchLongDoubleSum)
{
  Random rng(305);
  const int count = 3 * static_cast<int>(drb::kMinVerticesPerBackpropThread) + 5;
  const drb::Matrix3X<double> vertices = randomVertices(rng, count, 0.5);
  const std::vector<double> g = randomGradients(rng, count);
  const Vector6<double> q = rng.state();
  Eigen::Matrix<long double, 6, 1> sum = Eigen::Matrix<long double, 6, 1>::Zero();
  long double torque_scale = 0, force_scale = 0;
  for (int n = 0; n < count; ++n)
  {
    const Vector3<double> gi(g[3 * n], g[3 * n + 1], g[3 * n + 2]);
    sum += (refJacobian(q, Vector3<double>(vertices.col(n))).transpose() * gi).cast<long double>();
    torque_scale += vertices.col(n).norm() * gi.norm();
    force_scale += gi.norm();
  }
  const drb::VertexColumns<double> columns = vertices.transpose();
  const drb::BodyPose<double> pose(q);
  MaxTracker err;
  for (unsigned threads : { 1u, 2u, 3u, 8u })
  {
    const Vector6<double> dL = drb::backpropagateVertexGradients(pose, columns, g.data(), threads);
    EXPECT_EQ(dL, drb::backpropagateVertexGradients(pose, columns, g.data(), threads)) << threads << " threads";
    for (int j = 0; j < 6; ++j)
    {
      const double e = static_cast<double>(std::abs(dL[j] - sum[j]) / (j < 3 ? torque_scale : force_scale));
      err.update(e);
      // Each SIMD lane adds ~count/8 terms in sequence: the rounding is
      // ~sqrt(count/8) eps of the scale for random signs, count/8 eps =
      // 5.5e-12 at worst.
      EXPECT_LE(e, 1e-10) << threads << " threads, component " << j;
    }
  }
  std::printf("[measured] backprop by coordinate, %d vertices on 1/2/3/8 threads vs long double: %.3g eps\n", count,
              err.value / kEps);
}

// ---------------------------------------------------------------------------
// Seed typo regression (docs/derivation.md, "The seed's typos"): the seed
// prints dx/dphi without its parentheses,
//   p_y sin phi sin psi + cos phi sin th cos psi + p_z (...)
// (and the paper's published code has the same error). The formula as printed
// differs from the truth by (1 - p_y) cos phi sin th cos psi, so it must be
// caught whenever p_y != 1 and that product is not small.
TEST(SeedTypos, PrintedDxDphiFailsFiniteDifferencesAndOursPasses)
{
  Random rng(401);
  int caught = 0, states = 0;
  MaxTracker seed_other_entries;
  for (int s = 0; s < 100; ++s)
  {
    const Vector6<double> q = rng.state();
    Vector3<double> p0 = rng.vector(2.0);
    if (std::abs((1 - p0[1]) * std::cos(q[0]) * std::sin(q[1]) * std::cos(q[2])) < 0.05)
      continue;  // the typo is invisible (or too small to see by FD) there
    ++states;
    const Matrix36<double> J_fd = centralDifferenceJ(q, p0, refPosition<double>);
    const double tol = fdTolerance(p0, q);
    const Matrix36<double> seed = seedJacobianAsPrinted(q, p0, false);
    const Matrix36<double> seed_fixed = seedJacobianAsPrinted(q, p0, true);
    // The printed dx/dphi is caught by the same FD check that J passes...
    if (std::abs(seed(0, 0) - J_fd(0, 0)) > 1000 * tol)
      ++caught;
    // ...and it is the only wrong entry of section C.
    Matrix36<double> seed_rest = seed - J_fd;
    seed_rest(0, 0) = 0;
    seed_other_entries.update(maxAbs(seed_rest) / tol);
    EXPECT_LE(maxAbs(seed_rest), tol) << "q = " << q.transpose();
    EXPECT_LE(maxAbs(seed_fixed - J_fd), tol) << "q = " << q.transpose();
    EXPECT_LE(maxAbs(kernelJ(q, p0) - J_fd), tol) << "q = " << q.transpose();
    // Ours equals the parenthesised closed form to rounding.
    EXPECT_LE(maxAbs(kernelJ(q, p0) - seed_fixed) / p0.norm(), kLongFormTol) << "q = " << q.transpose();
  }
  ASSERT_GT(states, 50);
  EXPECT_EQ(caught, states) << "the FD check must reject the printed dx/dphi at every state used";
  std::printf("[measured] seed dx/dphi rejected at %d/%d states; other section-C entries at %.2g of FD tol\n", caught,
              states, seed_other_entries.value);
}

// ---------------------------------------------------------------------------

TEST(VertexJacobian, FloatAgreesWithDouble)
{
  Random rng(501);
  MaxTracker err_J, err_p, err_bp;
  for (int s = 0; s < 1000; ++s)
  {
    const Vector6<float> qf = rng.state().cast<float>();
    const Vector6<double> q = qf.cast<double>();
    const Vector3<float> p0f = rng.vertexOfNorm(rng.logUniform(1e-3, 1e3)).cast<float>();
    const Vector3<double> p0 = p0f.cast<double>();
    const drb::BodyPose<float> pose_f(qf);
    const drb::BodyPose<double> pose(q);
    const double e_J =
        maxAbs(drb::vertexJacobian(pose_f, p0f).cast<double>() - drb::vertexJacobian(pose, p0)) / p0.norm();
    const double e_p = maxAbs(drb::vertexPosition(pose_f, p0f).cast<double>() - drb::vertexPosition(pose, p0)) /
                       (p0.norm() + q.tail<3>().norm());
    // Backprop over 8 vertices.
    drb::Matrix3X<float> vf(3, 8);
    std::vector<float> gf(24);
    for (int i = 0; i < 8; ++i)
      vf.col(i) = rng.vector(1.0).cast<float>();
    for (float& x : gf)
      x = static_cast<float>(rng.uniform(-1, 1));
    const std::vector<double> gd(gf.begin(), gf.end());
    const drb::Matrix3X<double> vd = vf.cast<double>();
    double bp_scale = 0;  // sum |p0_i| |g_i| + sum |g_i|
    for (int i = 0; i < 8; ++i)
      bp_scale += (vd.col(i).norm() + 1) * Eigen::Vector3d(gd[3 * i], gd[3 * i + 1], gd[3 * i + 2]).norm();
    const double e_bp = maxAbs(drb::backpropagateVertexGradients(pose_f, vf, {}, gf.data()).cast<double>() -
                               drb::backpropagateVertexGradients(pose, vd, {}, gd.data())) /
                        bp_scale;
    err_J.update(e_J);
    err_p.update(e_p);
    err_bp.update(e_bp);
    ASSERT_LE(e_J, kFloatTol) << "q = " << q.transpose();
    ASSERT_LE(e_p, kFloatTol) << "q = " << q.transpose();
    ASSERT_LE(e_bp, kFloatTol) << "q = " << q.transpose();
  }
  std::printf("[measured] float vs double: J %.3g, p %.3g, backprop %.3g float eps\n", err_J.value / FLT_EPSILON,
              err_p.value / FLT_EPSILON, err_bp.value / FLT_EPSILON);
}
