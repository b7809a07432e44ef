// The equations of motion (rnea.h, rnea_derivatives.h, forward_dynamics.h)
// against independent computations, on every dynamics fixture (fixed-base
// chains, the Panda with its mimic finger, the floating tree, the floating
// 35-coordinate humanoid, an asymmetric free body):
//   - c against the Lagrange form sum_k dM/dx_k x'_k x' - 1/2 (x'^T dM/dx_j x')_j
//     (dM/dx is checked against the complex step of crba elsewhere);
//   - g against the complex step of the potential V = -sum m_l gamma . c_l,
//     with the COMs from forward kinematics alone;
//   - dtau/dx, dtau/dx' and dx''/dx, dx''/dx' against the complex step of
//     inverse and forward dynamics;
//   - the identities C x' = c, dtau/dx' = 2 C with the Christoffel C of dM/dx,
//     dM/dt - 2 C skew, FD(ID(x'')) = x'', (dx''/dtau) M = I;
//   - tau and x'' against 256-bit MPFR evaluations of the same kernels.
#include <complex>
#include <random>

#include <gtest/gtest.h>
#include <mpreal.h>
#include <unsupported/Eigen/MPRealSupport>

#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "diff_rigid_body/algorithm/mass_matrix_derivatives.h"
#include "../support/dynamics_fixtures.h"

namespace drb = diff_rigid_body;
using drb_test::dynamics::DynamicsBody;
using drb_test::dynamics::dynamicsBodies;
using drb_test::dynamics::relativeDifference;

namespace
{
using Complex = std::complex<double>;
constexpr double kStep = 1e-30;               // complex step (no cancellation)
constexpr double kIdentityTolerance = 1e-13;  // relative, identities of double results
constexpr double kComplexStepTolerance = 1e-12;  // relative, analytic against complex-step derivatives
constexpr double kMpfrTolerance = 32 * 2.220446049250313e-16;  // relative to max|reference|: a few ulp
const drb::Vector3<double> kGravity(0.4, -0.3, -9.81);  // [m/s^2], not axis-aligned

using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

/// dM/dx_j as d matrices.
std::vector<Matrix> massMatrixDerivatives(const drb::BodyModel& model, const Vector& x)
{
  const Eigen::Index d = x.size();
  drb::BodyWorkspace<double> ws(model);
  std::vector<double> flat(static_cast<std::size_t>(d * d * d));
  drb::massMatrixDerivatives(model, ws, x.data(), flat.data());
  std::vector<Matrix> out;
  for (Eigen::Index j = 0; j < d; ++j)
    out.push_back(Eigen::Map<Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(flat.data() + j * d * d, d, d));
  return out;
}

/// tau at (x, x', x'') with `gravity`.
Vector inverse(const drb::BodyModel& model, const Vector& x, const Vector& xd, const Vector& xdd,
               const drb::Vector3<double>& gravity)
{
  drb::BodyWorkspace<double> ws(model);
  Vector tau(x.size());
  drb::inverseDynamics(model, ws, x.data(), xd.data(), xdd.data(), gravity, tau.data());
  return tau;
}

/// d/dx_j (or d/dx'_j) of a complex-valued function of (x, x') by the complex step.
template <typename F>
Matrix complexStep(const Vector& x, const Vector& xd, bool by_rate, F&& f)
{
  const Eigen::Index d = x.size();
  Matrix out(d, d);
  for (Eigen::Index j = 0; j < d; ++j)
  {
    Eigen::VectorXcd xc = x.cast<Complex>(), xdc = xd.cast<Complex>();
    (by_rate ? xdc : xc)[j] += Complex(0, kStep);
    out.col(j) = f(xc, xdc).imag() / kStep;
  }
  return out;
}

class DynamicsIdentities : public ::testing::TestWithParam<std::size_t>
{
protected:
  const DynamicsBody& fixture() const { return dynamicsBodies()[GetParam()]; }
  const drb::BodyModel& model() const { return fixture().model(); }
  std::vector<drb_test::dynamics::Motion> motions() const
  {
    std::mt19937_64 rng(42 + GetParam());
    return { drb_test::dynamics::randomMotion(model(), rng), drb_test::dynamics::randomMotion(model(), rng) };
  }
};
}  // namespace

TEST_P(DynamicsIdentities, VelocityTermsAreTheLagrangeForm)
{
  for (const auto& m : motions())
  {
    const std::vector<Matrix> dM = massMatrixDerivatives(model(), m.x);
    Vector lagrange = Vector::Zero(m.x.size());
    for (Eigen::Index k = 0; k < m.x.size(); ++k)
    {
      lagrange += dM[static_cast<std::size_t>(k)] * m.xd * m.xd[k];
      lagrange[k] -= 0.5 * m.xd.dot(dM[static_cast<std::size_t>(k)] * m.xd);
    }
    const Vector c = inverse(model(), m.x, m.xd, Vector::Zero(m.x.size()), drb::Vector3<double>::Zero());
    EXPECT_LT(relativeDifference(c, lagrange), kIdentityTolerance) << fixture().name;
  }
}

TEST_P(DynamicsIdentities, GravityTermsAreTheGradientOfThePotential)
{
  for (const auto& m : motions())
  {
    const Vector g = inverse(model(), m.x, Vector::Zero(m.x.size()), Vector::Zero(m.x.size()), kGravity);
    drb::BodyWorkspace<Complex> ws(model());
    const Matrix dV = complexStep(m.x, m.xd, false, [&](const Eigen::VectorXcd& x, const Eigen::VectorXcd&) {
      drb::forwardKinematics(model(), ws, x.data());
      Complex V = 0;
      for (std::size_t s = 0; s < model().segments.size(); ++s)
      {
        const drb::MassProperties& own = model().segments[s].inertia;
        const Eigen::Vector3cd c = ws.R[s] * own.com.cast<Complex>() + ws.p[s];
        V -= own.mass * (kGravity[0] * c[0] + kGravity[1] * c[1] + kGravity[2] * c[2]);
      }
      return Eigen::VectorXcd::Constant(m.x.size(), V);
    });
    EXPECT_LT(relativeDifference(g, dV.row(0).transpose()), kComplexStepTolerance) << fixture().name;
  }
}

TEST_P(DynamicsIdentities, InverseDynamicsDerivativesMatchTheComplexStep)
{
  for (const auto& m : motions())
  {
    drb::BodyWorkspace<double> ws(model());
    Matrix dq(m.x.size(), m.x.size()), dqd(m.x.size(), m.x.size());
    drb::inverseDynamicsDerivatives(model(), ws, m.x.data(), m.xd.data(), m.xdd.data(), kGravity, dq, dqd);
    drb::BodyWorkspace<Complex> wc(model());
    const auto tau = [&](const Eigen::VectorXcd& x, const Eigen::VectorXcd& xd) {
      const Eigen::VectorXcd xdd = m.xdd.cast<Complex>();
      Eigen::VectorXcd out(x.size());
      drb::inverseDynamics(model(), wc, x.data(), xd.data(), xdd.data(), kGravity.cast<Complex>().eval(), out.data());
      return out;
    };
    EXPECT_LT(relativeDifference(dq, complexStep(m.x, m.xd, false, tau)), kComplexStepTolerance) << fixture().name;
    EXPECT_LT(relativeDifference(dqd, complexStep(m.x, m.xd, true, tau)), kComplexStepTolerance) << fixture().name;
  }
}

TEST_P(DynamicsIdentities, ChristoffelIdentities)
{
  for (const auto& m : motions())
  {
    const Eigen::Index d = m.x.size();
    const std::vector<Matrix> dM = massMatrixDerivatives(model(), m.x);
    Matrix C = Matrix::Zero(d, d), dM_dt = Matrix::Zero(d, d);
    for (Eigen::Index k = 0; k < d; ++k)
    {
      dM_dt += dM[static_cast<std::size_t>(k)] * m.xd[k];
      for (Eigen::Index i = 0; i < d; ++i)
        for (Eigen::Index j = 0; j < d; ++j)  // G_ijk x'_k
          C(i, j) += 0.5 * (dM[std::size_t(k)](i, j) + dM[std::size_t(j)](i, k) - dM[std::size_t(i)](j, k)) * m.xd[k];
    }
    drb::BodyWorkspace<double> ws(model());
    Matrix dq(d, d), dqd(d, d);
    drb::inverseDynamicsDerivatives(model(), ws, m.x.data(), m.xd.data(), m.xdd.data(), kGravity, dq, dqd);
    const Vector c = inverse(model(), m.x, m.xd, Vector::Zero(d), drb::Vector3<double>::Zero());
    EXPECT_LT(relativeDifference(0.5 * dqd, C), kIdentityTolerance) << fixture().name << ": dtau/dx' = 2 C";
    EXPECT_LT(relativeDifference(C * m.xd, c), kIdentityTolerance) << fixture().name << ": C x' = c";
    const Matrix N = dM_dt - 2 * C;
    EXPECT_LT((N + N.transpose()).cwiseAbs().maxCoeff() / std::max(1e-300, dM_dt.cwiseAbs().maxCoeff()),
              kIdentityTolerance)
        << fixture().name << ": dM/dt - 2 C skew";
  }
}

TEST_P(DynamicsIdentities, ForwardDynamicsInvertsInverseDynamics)
{
  for (const auto& m : motions())
  {
    const Eigen::Index d = m.x.size();
    const Vector tau = inverse(model(), m.x, m.xd, m.xdd, kGravity);
    drb::BodyWorkspace<double> ws(model());
    Vector xdd(d);
    Matrix dq(d, d), dqd(d, d), inverse_mass(d, d);
    ASSERT_EQ(drb::forwardDynamicsDerivatives(model(), ws, m.x.data(), m.xd.data(), tau.data(), kGravity, xdd.data(),
                                              dq, dqd, inverse_mass),
              -1);
    EXPECT_LT(relativeDifference(xdd, m.xdd), kIdentityTolerance * 100) << fixture().name;  // cond(M) enters
    drb::crba(model(), ws, m.x.data());
    EXPECT_LT((inverse_mass * ws.M - Matrix::Identity(d, d)).cwiseAbs().maxCoeff(), kIdentityTolerance * 100)
        << fixture().name;
    drb::BodyWorkspace<Complex> wc(model());
    const auto forward = [&](const Eigen::VectorXcd& x, const Eigen::VectorXcd& xd) {
      const Eigen::VectorXcd t = tau.cast<Complex>();
      Eigen::VectorXcd out(d);
      EXPECT_EQ(drb::forwardDynamics(model(), wc, x.data(), xd.data(), t.data(), kGravity.cast<Complex>().eval(),
                                     out.data()),
                -1);
      return out;
    };
    EXPECT_LT(relativeDifference(dq, complexStep(m.x, m.xd, false, forward)), kComplexStepTolerance * 100)
        << fixture().name;
    EXPECT_LT(relativeDifference(dqd, complexStep(m.x, m.xd, true, forward)), kComplexStepTolerance * 100)
        << fixture().name;
  }
}

TEST_P(DynamicsIdentities, InverseAndForwardDynamicsAtAFewUlpOfMpfr)
{
  mpfr::mpreal::set_default_prec(256);
  using Mp = mpfr::mpreal;
  using VectorMp = Eigen::Matrix<Mp, Eigen::Dynamic, 1>;
  for (const auto& m : motions())
  {
    const Eigen::Index d = m.x.size();
    const Vector tau = inverse(model(), m.x, m.xd, m.xdd, kGravity);
    drb::BodyWorkspace<Mp> wm(model());
    const VectorMp x = m.x.cast<Mp>(), xd = m.xd.cast<Mp>(), xdd = m.xdd.cast<Mp>(), t = m.tau.cast<Mp>();
    VectorMp tau_mp(d), xdd_mp(d);
    drb::inverseDynamics(model(), wm, x.data(), xd.data(), xdd.data(), kGravity.cast<Mp>().eval(), tau_mp.data());
    ASSERT_EQ(drb::forwardDynamics(model(), wm, x.data(), xd.data(), t.data(), kGravity.cast<Mp>().eval(), xdd_mp.data()),
              -1);
    drb::BodyWorkspace<double> ws(model());
    Vector xdd_double(d);
    ASSERT_EQ(drb::forwardDynamics(model(), ws, m.x.data(), m.xd.data(), m.tau.data(), kGravity, xdd_double.data()), -1);
    const Vector tau_ref = tau_mp.cast<double>(), xdd_ref = xdd_mp.cast<double>();
    EXPECT_LT(relativeDifference(tau, tau_ref), kMpfrTolerance) << fixture().name << ": tau";
    // x'' carries M's conditioning: a few ulp times cond(M).
    EXPECT_LT(relativeDifference(xdd_double, xdd_ref), 1e-12) << fixture().name << ": x''";
  }
}

INSTANTIATE_TEST_SUITE_P(Bodies, DynamicsIdentities, ::testing::Range<std::size_t>(0, dynamicsBodies().size()),
                         [](const ::testing::TestParamInfo<std::size_t>& info) {
                           return dynamicsBodies()[info.param].name;
                         });
