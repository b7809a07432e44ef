// Hard cases of the equations of motion, through what the node serves
// (SceneQueries::inverseDynamics, forwardDynamics):
//   - gimbal lock: at pitch pi/2 (+- 1e-k) inverse dynamics stays finite
//     and at a few ulp of MPFR (forward dynamics there:
//     test_gimbal_lock_dynamics.cpp);
//   - velocities of 1e3 rad/s;
//   - a coordinate that moves no mass: refused by forward dynamics, naming it;
//   - K = 1000 configurations in one call, equal to single calls bit for bit.
#include <cmath>

#include <gtest/gtest.h>
#include <mpreal.h>
#include <unsupported/Eigen/MPRealSupport>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "../support/dynamics_fixtures.h"
#include "../support/expect_throws.h"

namespace drb = diff_rigid_body;
using drb_test::dynamics::dynamicsBodies;
using drb_test::dynamics::relativeDifference;

namespace
{
using Vector = Eigen::VectorXd;
using Mp = mpfr::mpreal;
using VectorMp = Eigen::Matrix<Mp, Eigen::Dynamic, 1>;
constexpr double kEps = 2.220446049250313e-16;
constexpr double kHalfPi = 1.5707963267948966;

const drb_test::dynamics::DynamicsBody& brick()
{
  return dynamicsBodies().back();  // free_brick
}

/// tau at (x, x', x'') in 256-bit MPFR, as double.
Vector referenceTau(const drb::BodyModel& model, const Vector& x, const Vector& xd, const Vector& xdd)
{
  mpfr::mpreal::set_default_prec(256);
  drb::BodyWorkspace<Mp> ws(model);
  const VectorMp xm = x.cast<Mp>(), xdm = xd.cast<Mp>(), xddm = xdd.cast<Mp>();
  VectorMp tau(x.size());
  drb::inverseDynamics(model, ws, xm.data(), xdm.data(), xddm.data(), drb::standardGravity().cast<Mp>().eval(),
                       tau.data());
  return tau.cast<double>();
}

std::vector<double> asVector(const Vector& v)
{
  return std::vector<double>(v.data(), v.data() + v.size());
}
}  // namespace

TEST(DynamicsHardCases, GimbalLockInverseDynamicsStaysFiniteAtAFewUlp)
{
  const drb::SceneQueries queries(brick().scene);
  const drb::BodyModel& model = brick().model();
  for (const double offset : { 0.0, 1e-3, -1e-6, 1e-9, -1e-12 })
  {
    Vector x(6), xd(6), xdd(6);
    x << 0.3, kHalfPi + offset, -0.7, 1, 2, 3;
    xd << 0.5, -1.1, 2.0, 0.1, 0.2, 0.3;
    xdd << 1, 2, 3, 4, 5, 6;
    drb::InverseDynamicsAnswer answer;
    queries.inverseDynamics(queries.initialState(), {}, asVector(x), asVector(xd), asVector(xdd), true, true, answer);
    for (const auto* values : { &answer.tau, &answer.coriolis_matrices, &answer.dtau_dq, &answer.dtau_dqdot })
      for (double v : *values)
        EXPECT_TRUE(std::isfinite(v)) << "offset " << offset;
    const Vector tau = Eigen::Map<const Vector>(answer.tau.data(), 6);
    EXPECT_LT(relativeDifference(tau, referenceTau(model, x, xd, xdd)), 16 * kEps) << "offset " << offset;
  }
}

TEST(DynamicsHardCases, FastSpinAtAFewUlpOfMpfr)
{
  for (const auto& fixture : dynamicsBodies())
  {
    const drb::BodyModel& model = fixture.model();
    const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
    Vector x = Vector::LinSpaced(d, -0.8, 0.9), xd = Vector::Constant(d, 1e3), xdd = Vector::LinSpaced(d, -5, 5);
    drb::BodyWorkspace<double> ws(model);
    Vector tau(d);
    drb::inverseDynamics(model, ws, x.data(), xd.data(), xdd.data(), drb::standardGravity(), tau.data());
    EXPECT_LT(relativeDifference(tau, referenceTau(model, x, xd, xdd)), 64 * kEps) << fixture.name;
  }
}

TEST(DynamicsHardCases, CoordinateThatMovesNoMassIsRefusedByForwardDynamicsOnly)
{
  using namespace drb_test::urdf;
  const std::string urdf =
      robot(link("arm", inertial()) + drb_test::articulated::oneDofJoint("revolute", "world", "arm", "0 0 0", "0 0 0", "0 0 1") +
            link("flag") + drb_test::articulated::oneDofJoint("revolute", "arm", "flag", "1 0 0", "0 0 0", "0 0 1"));
  const drb::SceneQueries queries(drb::loadSceneFromUrdf(urdf));
  drb::ForwardDynamicsAnswer forward;
  DRB_EXPECT_THROWS_MESSAGE(queries.forwardDynamics(queries.initialState(), {}, {}, {}, {}, false, forward),
                            drb::InvalidArgumentError, "body 'arm'", "x[1]", "joint 'flag_joint'", "moves no mass");
  drb::InverseDynamicsAnswer inverse;
  queries.inverseDynamics(queries.initialState(), {}, {}, { 1.0, 2.0 }, { 0.5, 0.5 }, true, true, inverse);
  EXPECT_EQ(inverse.tau[1], 0.0);  // nothing to push
}

TEST(DynamicsHardCases, ThousandConfigurationsEqualSingleCallsBitForBit)
{
  const auto& fixture = dynamicsBodies()[dynamicsBodies().size() - 2];  // floating_humanoid, 35 coordinates
  const drb::SceneQueries queries(fixture.scene);
  const std::size_t d = queries.dofs(0), K = 1000;
  std::mt19937_64 rng(5);
  std::vector<double> q, qd, qdd;
  for (std::size_t k = 0; k < K; ++k)
  {
    const auto m = drb_test::dynamics::randomMotion(fixture.model(), rng);
    q.insert(q.end(), m.x.data(), m.x.data() + d);
    qd.insert(qd.end(), m.xd.data(), m.xd.data() + d);
    qdd.insert(qdd.end(), m.xdd.data(), m.xdd.data() + d);
  }
  drb::InverseDynamicsAnswer batch, single;
  drb::ForwardDynamicsAnswer fbatch, fsingle;
  queries.inverseDynamics(queries.initialState(), {}, q, qd, qdd, false, true, batch);
  queries.forwardDynamics(queries.initialState(), {}, q, qd, qdd, true, fbatch);
  for (std::size_t k = 0; k < K; k += 97)
  {
    const auto slice = [&](const std::vector<double>& v) {
      return std::vector<double>(v.begin() + long(k * d), v.begin() + long((k + 1) * d));
    };
    queries.inverseDynamics(queries.initialState(), {}, slice(q), slice(qd), slice(qdd), false, true, single);
    queries.forwardDynamics(queries.initialState(), {}, slice(q), slice(qd), slice(qdd), true, fsingle);
    EXPECT_TRUE(std::equal(single.tau.begin(), single.tau.end(), batch.tau.begin() + long(k * d))) << k;
    EXPECT_TRUE(std::equal(single.dtau_dq.begin(), single.dtau_dq.end(), batch.dtau_dq.begin() + long(k * d * d)))
        << k;
    EXPECT_TRUE(std::equal(fsingle.qddot.begin(), fsingle.qddot.end(), fbatch.qddot.begin() + long(k * d))) << k;
    EXPECT_TRUE(std::equal(fsingle.dqddot_dtau.begin(), fsingle.dqddot_dtau.end(),
                           fbatch.dqddot_dtau.begin() + long(k * d * d)))
        << k;
  }
}
