// The shipped launch file on the shipped scene: launch/server.launch with
// its defaults (urdf/demo_scene.urdf), and a second instance in its own
// namespace (the launch file's ns argument) on the fixture scene, with
// fixed_frame:=pedestal.
//
// Runs in demo_scene.test.
#include <cmath>

#include <gtest/gtest.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "server_client.h"

namespace drb_rostest
{
namespace
{
constexpr double kTfTolerance = 1e-9;        // m
constexpr double kLengthTolerance = 1e-12;   // m
constexpr double kAngleTolerance = 1e-12;    // rad
constexpr std::uint32_t kRockMeshVertices = 2562;  // urdf/meshes/rock.stl (demo_scene.urdf's comment)

Eigen::Isometry3d toIsometry(const geometry_msgs::Transform& transform)
{
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(transform.rotation.w, transform.rotation.x, transform.rotation.y,
                                  transform.rotation.z)
                   .toRotationMatrix();
  X.translation() << transform.translation.x, transform.translation.y, transform.translation.z;
  return X;
}
}  // namespace

TEST(DemoScene, GetBodiesThroughServerLaunch)
{
  ServerClient demo("/rigid_body_server");
  const drb::GetBodies::Response bodies = demo.getBodies();
  ASSERT_TRUE(bodies.success) << bodies.message;
  EXPECT_EQ(bodies.fixed_frame, "world");
  EXPECT_EQ(bodies.names, (std::vector<std::string>{ "knot", "rock" }));
  EXPECT_EQ(bodies.vertex_counts, (std::vector<std::uint32_t>{ 4096, 2626 }));
  ASSERT_EQ(bodies.masses.size(), 2u);
  // rock's mass includes the merged rock_handle.
  EXPECT_NEAR(bodies.masses[0], 0.28125334, 1e-15);
  EXPECT_NEAR(bodies.masses[1], 1.39997 + 0.05, 1e-15);

  // Initial state of knot: rpy of its joint, t = its origin (COM at the link origin).
  const drb::GetState::Response state = demo.getState({ "knot" });
  ASSERT_TRUE(state.success) << state.message;
  const Vector6d q = toVector(state.states.at(0));
  EXPECT_LE((rpyRotation(q[0], q[1], q[2]) - rpyRotation(0, 0, 0.3)).cwiseAbs().maxCoeff(), kAngleTolerance);
  EXPECT_LE((q.tail<3>() - Eigen::Vector3d(-0.2, 0.05, 0.457)).norm(), kLengthTolerance);
}

TEST(DemoScene, MergedRockHandleAgreesWithTf)
{
  ServerClient demo("/rigid_body_server");
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const ros::Time stamp =
      buffer.lookupTransform("world", "rock_handle", ros::Time(0), ros::Duration(10.0)).header.stamp;
  const Eigen::Isometry3d X = toIsometry(buffer.lookupTransform("world", "rock_handle", stamp).transform);
  // Frame from the URDF joint origins: rock at (0.2, -0.05, 0.48), handle at (0, 0, 0.045) pitched 0.4.
  const Eigen::Isometry3d expected =
      urdfPose(Eigen::Vector3d(0.2, -0.05, 0.48)) * urdfPose(Eigen::Vector3d(0, 0, 0.045), Eigen::Vector3d(0, 0.4, 0));
  EXPECT_LE((X.translation() - expected.translation()).norm(), kTfTolerance);
  EXPECT_LE((X.linear() - expected.linear()).cwiseAbs().maxCoeff(), kTfTolerance);

  // rock_handle's cylinder (64 vertices) follows rock's mesh vertices.
  const std::vector<Eigen::Vector3d> handle =
      transformed(urdfPose(Eigen::Vector3d(0, 0, 0.03)), cylinderVertices(0.01, 0.06));
  std::vector<std::uint32_t> indices;
  for (std::uint32_t k = 0; k < handle.size(); ++k)
    indices.push_back(kRockMeshVertices + k);
  const drb::GetVertexJacobians::Response answer = demo.getVertexJacobians("rock", {}, indices);
  ASSERT_TRUE(answer.success) << answer.message;
  double max_error = 0.0;
  for (std::size_t k = 0; k < handle.size(); ++k)
  {
    const double error = (X * handle[k] - positionOf(answer, k)).norm();
    max_error = std::max(max_error, error);
    EXPECT_LE(error, kTfTolerance) << "rock_handle vertex " << k;
  }
  std::printf("[ measured ] demo rock_handle: tf vs get_vertex_jacobians max error %.3e m\n", max_error);

  // The table is static: on /tf_static, at its joint origin.
  const Eigen::Isometry3d table =
      toIsometry(buffer.lookupTransform("world", "table", ros::Time(0), ros::Duration(10.0)).transform);
  EXPECT_LE((table.translation() - Eigen::Vector3d(0, 0, 0.4)).norm(), kTfTolerance);
}

TEST(DemoScene, SecondInstanceInItsOwnNamespaceWithAFixedFrame)
{
  ServerClient second("/second_scene/rigid_body_server");
  const drb::GetBodies::Response bodies = second.getBodies();
  ASSERT_TRUE(bodies.success) << bodies.message;
  EXPECT_EQ(bodies.names, (std::vector<std::string>{ "brick", "tet", "roller" }));
  EXPECT_EQ(bodies.fixed_frame, "pedestal");

  // States are expressed in ~fixed_frame: the initial link pose and COM seen from pedestal.
  const FixtureScene fixture = fixtureScene();
  const Eigen::Isometry3d pedestal_from_world = fixture.static_links.at(0).pose.inverse();
  const drb::GetState::Response state = second.getState();
  ASSERT_TRUE(state.success) << state.message;
  ASSERT_EQ(state.states.size(), fixture.bodies.size());
  for (std::size_t i = 0; i < fixture.bodies.size(); ++i)
  {
    const FixtureBody& body = fixture.bodies[i];
    const Eigen::Isometry3d link = pedestal_from_world * body.initial_link_pose;
    const Vector6d q = toVector(state.states[i]);
    EXPECT_LE((rpyRotation(q[0], q[1], q[2]) - link.linear()).cwiseAbs().maxCoeff(), kAngleTolerance) << body.name;
    EXPECT_LE((q.tail<3>() - link * body.com_offset).norm(), kLengthTolerance) << body.name;
  }

  // The instances are independent.
  ASSERT_TRUE(second.setState({ bodyState("tet", Vector6d::Constant(0.5)) }).success);
  ServerClient demo("/rigid_body_server");
  const drb::SetState::Response refused = demo.setState({ bodyState("tet", Vector6d::Constant(0.5)) });
  EXPECT_FALSE(refused.success) << "the demo scene has no body 'tet'";
}

}  // namespace drb_rostest
