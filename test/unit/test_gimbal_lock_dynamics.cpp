// Forward dynamics near a free root's gimbal lock, against the 256-bit
// M-route reference of gimbal_reference.h: pitch theta = +-(pi/2 - 10^-k),
// k = 1..12, for the free brick (a full inertia tensor) and the floating
// humanoid (35 coordinates). The answer exists at every one of these states,
// and the core's route (motion coordinates inside, the chart at the edge)
// keeps it to a few ulp:
//   x''                          within kAccelerationTolerance (1e-13),
//   dx''/dx, dx''/dx', M^-1      within kDerivativeTolerance (1e-9),
// normwise relative. Solving with M would lose eps / cos^2(theta): 1e-4 at
// k = 6, and refuse from k = 7. At the lock itself (|cos theta| below
// kGimbalLockCosine) forward dynamics is refused, naming cos(theta).

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "../support/dynamics_fixtures.h"
#include "../support/expect_throws.h"
#include "../support/gimbal_reference.h"

namespace drb = diff_rigid_body;
using drb_test::gimbal::Mp;
using drb_test::gimbal::MatrixMp;
using drb_test::gimbal::VectorMp;

namespace
{
constexpr double kAccelerationTolerance = 1e-13;  // normwise relative
constexpr double kDerivativeTolerance = 1e-9;     // normwise relative
const Eigen::Vector3d kGravity(0.4, -0.3, -9.81);  // [m/s^2]

const drb_test::dynamics::DynamicsBody& fixture(const std::string& name)
{
  for (const auto& body : drb_test::dynamics::dynamicsBodies())
    if (body.name == name)
      return body;
  throw std::runtime_error("no fixture " + name);
}

/// Every column, or the root's six and every `stride`-th joint.
std::vector<Eigen::Index> columnsToCheck(Eigen::Index d, Eigen::Index stride)
{
  std::vector<Eigen::Index> columns;
  for (Eigen::Index j = 0; j < d; ++j)
    if (j < 6 || (j - 6) % stride == 0)
      columns.push_back(j);
  return columns;
}

struct Errors
{
  double xdd = 0, by_x = 0, by_xd = 0, inverse_mass = 0;
};

/// Ours against the reference at one state; derivatives only on `columns`
/// (none: x'' alone).
Errors errorsAt(const drb::BodyModel& model, const drb_test::gimbal::State& s, const std::vector<Eigen::Index>& columns)
{
  mpfr::mpreal::set_default_prec(256);
  const Eigen::Index d = s.x.size();
  drb::BodyWorkspace<double> ws(model);
  Eigen::VectorXd xdd(d);
  Eigen::MatrixXd by_x(d, d), by_xd(d, d), inverse_mass(d, d);
  EXPECT_EQ(drb::forwardDynamicsDerivatives(model, ws, s.x.data(), s.xd.data(), s.tau.data(), kGravity, xdd.data(),
                                            by_x, by_xd, inverse_mass),
            -1);
  const VectorMp reference =
      drb_test::gimbal::referenceForwardDynamics(model, s.x.cast<Mp>(), s.xd.cast<Mp>(), s.tau.cast<Mp>(), kGravity);
  Errors e;
  e.xdd = drb_test::gimbal::relativeError(xdd, MatrixMp(reference), { 0 });
  if (columns.empty())
    return e;
  e.by_x = drb_test::gimbal::relativeError(
      by_x, drb_test::gimbal::referenceDerivative(model, s.x, s.xd, s.tau, kGravity, false, columns), columns);
  e.by_xd = drb_test::gimbal::relativeError(
      by_xd, drb_test::gimbal::referenceDerivative(model, s.x, s.xd, s.tau, kGravity, true, columns), columns);
  drb::BodyWorkspace<Mp> wm(model);
  drb::crba(model, wm, s.x.cast<Mp>().eval().data());
  const MatrixMp inverse = wm.M.inverse();
  std::vector<Eigen::Index> all(static_cast<std::size_t>(d));
  for (Eigen::Index j = 0; j < d; ++j)
    all[static_cast<std::size_t>(j)] = j;
  e.inverse_mass = drb_test::gimbal::relativeError(inverse_mass, inverse, all);
  return e;
}

void expectWithinTolerances(const std::string& name, const drb::BodyModel& model, Eigen::Index stride,
                            int derivative_every)
{
  const auto states = drb_test::gimbal::gimbalStates(model, 11);
  for (std::size_t i = 0; i < states.size(); ++i)
  {
    const auto& s = states[i];
    const bool derivatives = static_cast<int>(i) % derivative_every == 0 || s.k == 12;
    const Errors e = errorsAt(model, s, derivatives ? columnsToCheck(s.x.size(), stride) : std::vector<Eigen::Index>{});
    const std::string at = name + " at theta = " + (s.sign > 0 ? "" : "-") + "(pi/2 - 1e-" + std::to_string(s.k) + ")";
    EXPECT_LT(e.xdd, kAccelerationTolerance) << at << ": x''";
    if (!derivatives)
      continue;
    EXPECT_LT(e.by_x, kDerivativeTolerance) << at << ": dx''/dx";
    EXPECT_LT(e.by_xd, kDerivativeTolerance) << at << ": dx''/dx'";
    EXPECT_LT(e.inverse_mass, kDerivativeTolerance) << at << ": M^-1";
  }
}
}  // namespace

TEST(GimbalLockDynamics, FreeBodyForwardDynamicsAndDerivativesAtEveryK)
{
  expectWithinTolerances("free_brick", fixture("free_brick").model(), 1, 1);
}

TEST(GimbalLockDynamics, FloatingHumanoidForwardDynamicsAtEveryKAndDerivativesAtSome)
{
  // x'' at all 24 states; derivatives (the root's six columns and every
  // 7th joint's) at every 6th state and at k = 12: each reference column
  // is two 256-bit forward dynamics.
  expectWithinTolerances("floating_humanoid", fixture("floating_humanoid").model(), 7, 6);
}

TEST(GimbalLockDynamics, RefusedOnlyWhereTheChartIsSingular)
{
  const auto& brick = fixture("free_brick");
  const drb::SceneQueries queries(brick.scene);
  drb::ForwardDynamicsAnswer answer;
  const std::vector<double> tau{ 1, 2, 3, 4, 5, 6 };
  const double half_pi = M_PI / 2;  // cos = 6.1e-17
  for (const double theta : { half_pi, std::nextafter(half_pi, 4.0), -half_pi })
  {
    const std::vector<double> at_lock{ 0.3, theta, -0.7, 1, 2, 3 };
    DRB_EXPECT_THROWS_MESSAGE(queries.forwardDynamics(queries.initialState(), {}, at_lock, {}, tau, false, answer),
                              drb::InvalidArgumentError, "body 'brick'", "gimbal lock", "cos(theta) = ");
  }
  // Four ulp of theta further out, |cos(theta)| = 9.4e-16 > kGimbalLockCosine: answered, finite.
  double theta = half_pi;
  for (int i = 0; i < 4; ++i)
    theta = std::nextafter(theta, 0.0);
  ASSERT_GT(std::abs(std::cos(theta)), drb::kGimbalLockCosine);
  queries.forwardDynamics(queries.initialState(), {}, { 0.3, theta, -0.7, 1, 2, 3 }, {}, tau, true, answer);
  for (const auto* values : { &answer.qddot, &answer.dqddot_dq, &answer.dqddot_dqdot, &answer.dqddot_dtau })
    for (double v : *values)
      EXPECT_TRUE(std::isfinite(v));
}
