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

#include "server_under_test.h"

namespace drb_rostest
{
namespace
{
constexpr double kTfTolerance = 1e-9;        // m
constexpr double kLengthTolerance = 1e-12;   // m
constexpr double kAngleTolerance = 1e-12;    // rad
constexpr std::uint32_t kRockMeshVertices = 2562;  // urdf/meshes/rock.stl (demo_scene.urdf's comment)
}  // namespace

TEST(DemoScene, GetBodiesThroughServerLaunch)
{
  RigidBodyClient demo(ros::NodeHandle(), "/rigid_body_server", ros::Duration(60.0));
  const diff_rigid_body_ros::Bodies bodies = demo.bodies();
  EXPECT_EQ(bodies.fixed_frame, "world");
  EXPECT_EQ(bodies.names, (std::vector<std::string>{ "knot", "rock" }));
  EXPECT_EQ(bodies.vertex_counts, (std::vector<std::uint32_t>{ 4096, 2626 }));
  ASSERT_EQ(bodies.masses.size(), 2u);
  // rock's mass includes the merged rock_handle.
  EXPECT_NEAR(bodies.masses[0], 0.28125334, 1e-15);
  EXPECT_NEAR(bodies.masses[1], 1.39997 + 0.05, 1e-15);

  // Initial state of knot: rpy of its joint, t = its origin (COM at the link origin).
  const Vector6d q = demo.getState({ "knot" }).at(0).second;
  EXPECT_LE((refRotation(q[0], q[1], q[2]) - refRotation(0.0, 0.0, 0.3)).cwiseAbs().maxCoeff(), kAngleTolerance);
  EXPECT_LE((q.tail<3>() - Eigen::Vector3d(-0.2, 0.05, 0.457)).norm(), kLengthTolerance);
}

TEST(DemoScene, MergedRockHandleAgreesWithTf)
{
  RigidBodyClient demo(ros::NodeHandle(), "/rigid_body_server", ros::Duration(60.0));
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
  const Eigen::Matrix3Xd positions = demo.vertexJacobians("rock", nullptr, indices).positions;
  ASSERT_EQ(static_cast<std::size_t>(positions.cols()), handle.size());
  double max_error = 0.0;
  for (std::size_t k = 0; k < handle.size(); ++k)
  {
    const double error = (X * handle[k] - positions.col(k)).norm();
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
  RigidBodyClient second(ros::NodeHandle(), "/second_scene/rigid_body_server", ros::Duration(60.0));
  const diff_rigid_body_ros::Bodies bodies = second.bodies();
  EXPECT_EQ(bodies.names, (std::vector<std::string>{ "brick", "tet", "roller" }));
  EXPECT_EQ(bodies.fixed_frame, "pedestal");

  // States are expressed in ~fixed_frame: the initial link pose and COM seen from pedestal.
  const FixtureScene fixture = fixtureScene();
  const Eigen::Isometry3d pedestal_from_world = fixture.static_links.at(0).pose.inverse();
  const NamedStates state = second.getState();
  ASSERT_EQ(state.size(), fixture.bodies.size());
  for (std::size_t i = 0; i < fixture.bodies.size(); ++i)
  {
    const FixtureBody& body = fixture.bodies[i];
    const Eigen::Isometry3d link = pedestal_from_world * body.initial_link_pose;
    const Vector6d& q = state[i].second;
    EXPECT_LE((refRotation(q[0], q[1], q[2]) - link.linear()).cwiseAbs().maxCoeff(), kAngleTolerance) << body.name;
    EXPECT_LE((q.tail<3>() - link * body.com_offset).norm(), kLengthTolerance) << body.name;
  }

  // The instances are independent (and the second is left as it was found).
  const NamedStates saved = second.getState();
  second.setState("tet", Vector6d::Constant(0.5));
  RigidBodyClient demo(ros::NodeHandle(), "/rigid_body_server", ros::Duration(60.0));
  EXPECT_THROW(demo.setState("tet", Vector6d::Constant(0.5)), ServiceError) << "the demo scene has no body 'tet'";
  second.setState(saved);
}

}  // namespace drb_rostest
