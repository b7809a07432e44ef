// Frames that do not move with the body (docs/interface.md, ~get_frame_jacobians):
// a static link below the URDF's root and the fixed frame itself answer their
// fixed pose, zero Jacobian columns and zero acceleration bias. The expected
// poses are the URDF's own numbers, not the loader's.
#include <cmath>
#include <cstdint>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "../support/plumbing_scenes.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using namespace drb_test::urdf;

namespace
{
// world -> table (fixed, 0.5 m up, rotated 90 deg about z) -> box (floating, 1 m above the table).
const std::string kTableScene =
    robot(link("table", collision(boxGeometry("1 1 1"))) + link("box", inertial()) +
          joint("fixed", "world", "table", "<origin xyz=\"0 0 0.5\" rpy=\"0 0 1.5707963267948966\"/>") +
          floatingJoint("box", "<origin xyz=\"0 0 1\"/>", "table"));

TEST(StaticFrames, AStaticLinkAndTheFixedFrameHaveTheirPoseAndNoColumns)
{
  const drb::SceneQueries queries(drb::loadSceneFromUrdf(kTableScene, drb::SceneOptions()), drb::standardGravity());
  const std::vector<double> q{ 0.3, -0.2, 0.1, 0.4, 0.5, 1.6 }, qdot{ 1, 2, 3, 4, 5, 6 };
  drb::FrameJacobianAnswer answer;
  for (std::uint32_t reference = 0; reference < 3; ++reference)
  {
    queries.frameJacobians(queries.initialState(), "box", { "table", "world", "box" }, q, qdot, reference, true,
                           answer);
    ASSERT_EQ(answer.frames, (std::vector<std::string>{ "table", "world", "box" }));
    ASSERT_EQ(answer.dofs, 6u);
    // table: p = (0, 0, 0.5), R = Rz(pi/2) row-major.
    const std::vector<double> table_pose{ 0, 0, 0.5, 0, -1, 0, 1, 0, 0, 0, 0, 1 };
    const std::vector<double> world_pose{ 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    for (int i = 0; i < 12; ++i)
    {
      EXPECT_NEAR(answer.poses[i], table_pose[i], 1e-15) << "table pose value " << i;
      EXPECT_EQ(answer.poses[12 + i], world_pose[i]) << "world pose value " << i;
    }
    for (int i = 0; i < 2 * 36; ++i)
      EXPECT_EQ(answer.jacobians[i], 0.0) << "static frame column value " << i << ", reference " << reference;
    for (int i = 0; i < 12; ++i)
      EXPECT_EQ(answer.acceleration_bias[i], 0.0) << "static frame bias value " << i;
    // The moving frame in the same answer is not zero: its position is q's translation.
    EXPECT_NEAR(answer.poses[24 + 0], 0.4, 1e-15);
    EXPECT_NEAR(answer.poses[24 + 2], 1.6, 1e-15);
    double moving = 0.0;
    for (int i = 72; i < 108; ++i)
      moving += std::abs(answer.jacobians[i]);
    EXPECT_GT(moving, 1.0);
  }
}

// Each thread keeps the resolution of its last request's body and frames: a request on another
// scene with the same names, or with or without the acceleration bias, must still get the answer
// a fresh thread (nothing kept) gets, bit for bit.
TEST(StaticFrames, ARequestAfterAnotherSceneOrOptionGetsAFreshThreadsAnswer)
{
  // Another scene with the same names, the table higher and after a floor (so its static index differs).
  const std::string higher_table =
      robot(link("floor", collision(boxGeometry("2 2 0.1"))) + link("table", collision(boxGeometry("1 1 1"))) +
            link("box", inertial()) + joint("fixed", "world", "floor", "<origin xyz=\"0 0 -0.05\"/>") +
            joint("fixed", "world", "table", "<origin xyz=\"0 0 0.7\"/>") +
            floatingJoint("box", "<origin xyz=\"0 0 1\"/>", "table"));
  const drb::SceneQueries low(drb::loadSceneFromUrdf(kTableScene, drb::SceneOptions()), drb::standardGravity());
  const drb::SceneQueries high(drb::loadSceneFromUrdf(higher_table, drb::SceneOptions()), drb::standardGravity());
  const std::vector<double> q{ 0.3, -0.2, 0.1, 0.4, 0.5, 1.6 }, qdot{ 1, 2, 3, 4, 5, 6 };
  const std::vector<std::string> frames{ "table", "box" };
  auto ask = [&](const drb::SceneQueries& queries, bool bias) {
    drb::FrameJacobianAnswer answer;
    queries.frameJacobians(queries.initialState(), "box", frames, q, qdot, 2, bias, answer);
    return answer;
  };
  auto askOnFreshThread = [&](const drb::SceneQueries& queries, bool bias) {
    drb::FrameJacobianAnswer answer;
    std::thread([&] { answer = ask(queries, bias); }).join();
    return answer;
  };
  for (const auto& [queries, bias] : { std::make_pair(&low, true), std::make_pair(&high, true),
                                       std::make_pair(&high, false), std::make_pair(&low, false),
                                       std::make_pair(&low, true) })
  {
    const drb::FrameJacobianAnswer kept = ask(*queries, bias), fresh = askOnFreshThread(*queries, bias);
    EXPECT_EQ(kept.poses, fresh.poses);
    EXPECT_EQ(kept.jacobians, fresh.jacobians);
    EXPECT_EQ(kept.acceleration_bias, fresh.acceleration_bias);
    EXPECT_EQ(kept.poses[2], queries == &low ? 0.5 : 0.7);  // the table's height in this scene
  }
}
// Each thread keeps its last frame request's workspace too: requests that alternate between
// bodies of 9, 2 and 6 coordinates on one scene, by the same thread, must each get the answer a
// fresh thread gets, bit for bit.
TEST(StaticFrames, ARequestForAnotherBodyGetsAFreshThreadsAnswer)
{
  const drb::SceneQueries queries(drb_test::plumbing::scene());
  const std::vector<std::pair<std::string, std::vector<double>>> requests{
    { "arm", { 0.1, 0.2, 0.3, 1.0, 2.0, 3.0, 0.4, -0.5, 0.05 } },
    { "crane", { 0.7, 0.25 } },
    { "arm", { -0.3, 1.1, 0.2, 0.5, 0.0, -1.0, 1.2, 0.3, -0.1 } },
    { "cube", { 0.3, -0.2, 0.1, 0.4, 0.5, 1.6 } },
    { "crane", { -1.1, 0.6 } },
  };
  for (const auto& [body, q] : requests)
  {
    const std::vector<double> qdot(q.size(), 0.5);
    auto ask = [&, &body = body, &q = q](drb::FrameJacobianAnswer& answer) {
      queries.frameJacobians(queries.initialState(), body, {}, q, qdot, 0, true, answer);
    };
    drb::FrameJacobianAnswer kept, fresh;
    ask(kept);
    std::thread([&] { ask(fresh); }).join();
    EXPECT_EQ(kept.frames, fresh.frames) << body;
    EXPECT_EQ(kept.poses, fresh.poses) << body;
    EXPECT_EQ(kept.jacobians, fresh.jacobians) << body;
    EXPECT_EQ(kept.acceleration_bias, fresh.acceleration_bias) << body;
  }
}

// A reused answer (the node keeps one per thread) holds each request's frame names and values,
// whatever the request before it named: more frames, fewer, or the same in another order.
TEST(StaticFrames, AReusedAnswerHoldsEachRequestsFrames)
{
  const drb::SceneQueries queries(drb::loadSceneFromUrdf(kTableScene, drb::SceneOptions()), drb::standardGravity());
  const std::vector<double> q{ 0.3, -0.2, 0.1, 0.4, 0.5, 1.6 };
  drb::FrameJacobianAnswer reused;
  for (const std::vector<std::string>& frames :
       std::vector<std::vector<std::string>>{ { "table", "world", "box" }, { "box", "table" }, { "world" },
                                              { "box", "world", "table" }, { "box" } })
  {
    drb::FrameJacobianAnswer fresh;
    queries.frameJacobians(queries.initialState(), "box", frames, q, {}, 2, false, reused);
    queries.frameJacobians(queries.initialState(), "box", frames, q, {}, 2, false, fresh);
    EXPECT_EQ(reused.frames, frames);
    EXPECT_EQ(reused.poses, fresh.poses);
    EXPECT_EQ(reused.jacobians, fresh.jacobians);
  }
}
}  // namespace
