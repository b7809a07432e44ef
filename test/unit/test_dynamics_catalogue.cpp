// The bad-input rows of ~inverse_dynamics, ~forward_dynamics,
// ~get_frame_jacobians and ~get_center_of_mass (D): each
// refused before anything is computed (lengths, NaN, unknown bodies, answers
// over the budget) or after (a singular M for forward dynamics), on the
// two free bodies cube and ball of urdf::twoBodies() and the plumbing
// scene's crane (fixed base). Run by the catalogue test of
// test_bad_input_catalogue.cpp, which also checks that docs/robustness.md
// quotes each message.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "../support/catalogue_row.h"
#include "../support/plumbing_scenes.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;

namespace drb_test
{
namespace catalogue
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const drb::SceneQueries& freeBodies()
{
  static const drb::SceneQueries queries(drb::loadSceneFromUrdf(urdf::twoBodies()));
  return queries;
}

std::string inverse(const std::vector<std::string>& bodies, const std::vector<double>& q,
                    const std::vector<double>& qdot, const std::vector<double>& qddot, bool matrices = false)
{
  drb::InverseDynamicsAnswer answer;
  freeBodies().inverseDynamics(freeBodies().initialState(), bodies, q, qdot, qddot, matrices, matrices, answer);
  return "accepted: " + std::to_string(answer.cos_theta.size()) + " configurations x bodies";
}

std::string forward(const std::vector<std::string>& bodies, const std::vector<double>& q,
                    const std::vector<double>& qdot, const std::vector<double>& tau, bool derivatives = false)
{
  drb::ForwardDynamicsAnswer answer;
  freeBodies().forwardDynamics(freeBodies().initialState(), bodies, q, qdot, tau, derivatives, answer);
  return "accepted: " + std::to_string(answer.cos_theta.size()) + " configurations x bodies";
}

std::string frames(const std::string& body, const std::vector<std::string>& names, const std::vector<double>& q,
                   const std::vector<double>& qdot, std::uint32_t reference)
{
  drb::FrameJacobianAnswer answer;
  freeBodies().frameJacobians(freeBodies().initialState(), body, names, q, qdot, reference, true, answer);
  return "accepted: " + std::to_string(answer.frames.size()) + " frames x " + std::to_string(answer.cos_theta.size()) +
         " configurations";
}

/// q of one configuration of cube at pitch `theta` [rad].
std::vector<double> cubeAt(double theta)
{
  return { 0.1, theta, 0.3, 0, 0, 1 };
}
}  // namespace

std::vector<Row> dynamicsRows()
{
  const double half_pi = 1.5707963267948966;
  return {
    { "D01", "inverse_dynamics: unknown body", Expect::Refused, "InvalidArgumentError", "unknown body 'ghost'",
      [] { return inverse({ "ghost" }, {}, {}, {}); } },
    { "D02", "inverse_dynamics: q of 7 values for one 6-dof body", Expect::Refused, "InvalidArgumentError",
      "q: expected a multiple of 6 values", [] { return inverse({ "cube" }, std::vector<double>(7, 0.0), {}, {}); } },
    { "D03", "inverse_dynamics: qdot of 6 values for 2 configurations", Expect::Refused, "InvalidArgumentError",
      "qdot: expected 12 values", [] { return inverse({ "cube" }, std::vector<double>(12, 0.0), std::vector<double>(6, 1.0), {}); } },
    { "D04", "inverse_dynamics: qddot[4] NaN", Expect::Refused, "InvalidArgumentError", "qddot[4]: not finite",
      [] { return inverse({ "cube" }, {}, {}, { 0, 0, 0, 0, kNaN, 0 }); } },
    { "D05", "inverse_dynamics: q NaN", Expect::Refused, "InvalidArgumentError", "q[1]: not finite",
      [] { return inverse({ "cube" }, { 0, kNaN, 0, 0, 0, 0 }, {}, {}); } },
    { "D06", "inverse_dynamics with matrices: more configurations than the budget (10^5 x 2 bodies)",
      Expect::Refused, "InvalidArgumentError", "answer values",
      [] { return inverse({}, std::vector<double>(12 * 100000, 0.0), {}, {}, true); } },
    { "D07", "inverse_dynamics: a free body at gimbal lock (pitch pi/2)", Expect::Accepted, "", "",
      [=] {
        EXPECT_EQ(inverse({ "cube" }, cubeAt(half_pi), { 1, 2, 3, 4, 5, 6 }, { 1, 1, 1, 1, 1, 1 }, true),
                  "accepted: 1 configurations x bodies");
        return std::string("accepted: tau, c, g, C and the derivatives finite (M is never inverted)");
      } },
    { "D08", "forward_dynamics: tau of 5 values for one 6-dof body", Expect::Refused, "InvalidArgumentError",
      "tau: expected 6 values", [] { return forward({ "cube" }, {}, {}, std::vector<double>(5, 0.0)); } },
    { "D09", "forward_dynamics: qdot +Inf", Expect::Refused, "InvalidArgumentError", "qdot[0]: not finite",
      [] { return forward({ "cube" }, {}, { std::numeric_limits<double>::infinity(), 0, 0, 0, 0, 0 }, {}); } },
    { "D10", "forward_dynamics: configuration 1 of 2 at gimbal lock (pitch pi/2)", Expect::Refused,
      "InvalidArgumentError", "q (configuration 1): body 'cube': M(x) is singular",
      [=] {
        std::vector<double> q = cubeAt(0.2), locked = cubeAt(half_pi);
        q.insert(q.end(), locked.begin(), locked.end());
        return forward({ "cube" }, q, {}, {});
      } },
    { "D11", "forward_dynamics: a joint that moves no mass", Expect::Refused, "InvalidArgumentError",
      "moves no mass",
      [] {
        drb::BodyModel crane = plumbing::crane();
        for (drb::Segment& segment : crane.segments)
          segment.inertia = drb::MassProperties();
        static const drb::SceneQueries queries(plumbing::scene(plumbing::arm(), crane));
        drb::ForwardDynamicsAnswer answer;
        queries.forwardDynamics(queries.initialState(), { "crane" }, {}, {}, {}, false, answer);
        return std::string("accepted");
      } },
    { "D12", "forward_dynamics with derivatives, 3 configurations of both bodies", Expect::Accepted, "", "",
      [] {
        EXPECT_EQ(forward({}, std::vector<double>(36, 0.25), {}, {}, true), "accepted: 6 configurations x bodies");
        return std::string("accepted: x'', dx''/dx, dx''/dx' and M^-1 per configuration and body");
      } },
    { "D13", "get_frame_jacobians: a frame that is not a link of the body", Expect::Refused, "InvalidArgumentError",
      "frames[1]: unknown frame 'ghost'", [] { return frames("cube", { "cube", "ghost" }, {}, {}, 0); } },
    { "D14", "get_frame_jacobians: reference 3", Expect::Refused, "InvalidArgumentError", "reference: 3 is not one of",
      [] { return frames("cube", {}, {}, {}, 3); } },
    { "D15", "get_frame_jacobians: qdot of 5 values for one configuration", Expect::Refused,
      "InvalidArgumentError", "qdot: expected 6 values",
      [] { return frames("cube", {}, std::vector<double>(6, 0.0), std::vector<double>(5, 0.0), 2); } },
    { "D16", "get_frame_jacobians: q NaN", Expect::Refused, "InvalidArgumentError", "q[2]: not finite",
      [] { return frames("cube", {}, { 0, 0, kNaN, 0, 0, 0 }, {}, 1); } },
    { "D17", "get_frame_jacobians: a free body at gimbal lock, 2 configurations", Expect::Accepted, "", "",
      [=] {
        std::vector<double> q = cubeAt(0.2), locked = cubeAt(half_pi);
        q.insert(q.end(), locked.begin(), locked.end());
        EXPECT_EQ(frames("cube", {}, q, std::vector<double>(12, 1.0), 0), "accepted: 1 frames x 2 configurations");
        return std::string("accepted: poses, J and J'x' finite (J is defined on the chart's singular set too)");
      } },
    { "D18", "get_center_of_mass: a body without mass", Expect::Refused, "InvalidArgumentError", "has no mass",
      [] {
        drb::BodyModel crane = plumbing::crane();
        for (drb::Segment& segment : crane.segments)
          segment.inertia = drb::MassProperties();
        static const drb::SceneQueries queries(plumbing::scene(plumbing::arm(), crane));
        drb::CenterOfMassAnswer answer;
        queries.centerOfMass(queries.initialState(), { "crane" }, {}, {}, true, answer);
        return std::string("accepted");
      } },
  };
}

}  // namespace catalogue
}  // namespace drb_test
