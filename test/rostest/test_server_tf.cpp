// tf agrees with the services: each body link frame and merged link frame
// looked up from tf (tf2_ros::Buffer + TransformListener), applied to that
// link's geometry as the fixture URDF gives it (fixture_scene.h), lands on
// the positions get_vertex_jacobians returns, at the initial state and after
// set_state. Static links are on /tf_static only; body frames go out on /tf
// in one message per publication.
//
// Runs in tf.test (fresh node). Every test leaves the node's state as it
// found it (RestoresState), so the tests run in any order.
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>

#include <gtest/gtest.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "server_under_test.h"

namespace drb_rostest
{
namespace
{
/// tf against service positions: the quaternion round trip costs ~1e-16 m
/// per metre; this is the contract's tolerance.
constexpr double kTfTolerance = 1e-9;  // m
/// tf rotations against the fixture's joint origins.
constexpr double kRotationTolerance = 1e-9;  // 1
const double kTimeout = 10.0;  // s

const FixtureScene& fixture()
{
  static const FixtureScene scene = fixtureScene();
  return scene;
}

/// Collects the TFMessages of a topic.
class TfRecorder
{
public:
  explicit TfRecorder(const std::string& topic)
  {
    subscriber_ = ros::NodeHandle().subscribe(topic, 100, &TfRecorder::onMessage, this);
  }
  std::vector<tf2_msgs::TFMessage> messages()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  /// Child frames seen so far.
  std::set<std::string> frames()
  {
    std::set<std::string> names;
    for (const tf2_msgs::TFMessage& message : messages())
      for (const geometry_msgs::TransformStamped& t : message.transforms)
        names.insert(t.child_frame_id);
    return names;
  }

private:
  void onMessage(const tf2_msgs::TFMessage::ConstPtr& message)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back(*message);
  }
  std::mutex mutex_;
  std::vector<tf2_msgs::TFMessage> messages_;
  ros::Subscriber subscriber_;
};

class Tf : public RestoresState
{
protected:
  Tf() : buffer_(ros::Duration(30.0)), listener_(buffer_) {}

  /// Whether the buffer holds every fixture link's frame at `stamp`.
  bool everyLinkAt(const ros::Time& stamp)
  {
    for (const FixtureBody& body : fixture().bodies)
      for (const FixtureLink& link : body.links)
        if (!buffer_.canTransform(fixture().fixed_frame, link.name, stamp))
          return false;
    return true;
  }

  /// The stamp of the first /tf publication of `frame` strictly after `after`, once every
  /// fixture link's frame at that stamp has arrived.
  ros::Time waitForStampAfter(const std::string& frame, const ros::Time& after)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
    while (ros::WallTime::now() < deadline)
    {
      try
      {
        const geometry_msgs::TransformStamped latest =
            buffer_.lookupTransform(fixture().fixed_frame, frame, ros::Time(0));
        // The listener's thread inserts a publication's frames one by one: wait for all of them.
        if (latest.header.stamp > after && everyLinkAt(latest.header.stamp))
          return latest.header.stamp;
      }
      catch (const tf2::TransformException&)
      {
      }
      ros::WallDuration(0.005).sleep();
    }
    throw std::runtime_error("no tf for '" + frame + "' newer than the request within " + std::to_string(kTimeout) +
                             " s");
  }

  /// Every link frame at `stamp` (all frames of a publication share it),
  /// applied to the link's geometry, against the service's positions.
  void expectTfAgreesWithPositions(const ros::Time& stamp, const std::string& when)
  {
    double max_error = 0.0;
    for (const FixtureBody& body : fixture().bodies)
    {
      const Eigen::Matrix3Xd positions = server().vertexJacobians(body.name).positions;
      ASSERT_EQ(static_cast<std::size_t>(positions.cols()), body.p0.size()) << body.name;
      for (std::size_t l = 0; l < body.links.size(); ++l)
      {
        const FixtureLink& link = body.links[l];
        const Eigen::Isometry3d X =
            toIsometry(buffer_.lookupTransform(fixture().fixed_frame, link.name, stamp).transform);
        for (std::size_t k = 0; k < link.vertices.size(); ++k)
        {
          const std::size_t index = body.vertex_index[l][k];
          const double error = (X * link.vertices[k] - positions.col(index)).norm();
          max_error = std::max(max_error, error);
          EXPECT_LE(error, kTfTolerance) << when << ": link '" << link.name << "' geometry vertex " << k << " (body '"
                                         << body.name << "' vertex " << index << "): tf gives "
                                         << (X * link.vertices[k]).transpose() << ", service "
                                         << positions.col(index).transpose();
        }
      }
    }
    RecordProperty("max_tf_error_" + when, std::to_string(max_error));
    std::printf("[ measured ] tf vs get_vertex_jacobians (%s): max error %.3e m\n", when.c_str(), max_error);
  }

  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_;
};
}  // namespace

TEST_F(Tf, InitialFramesFollowJointOriginsAndAgreeWithPositions)
{
  // A publication stamped after the start of the test carries the state
  // the test found (the initial one: every test restores it).
  const ros::Time stamp = waitForStampAfter("brick", ros::Time::now());
  for (const FixtureBody& body : fixture().bodies)
    for (const FixtureLink& link : body.links)
    {
      const Eigen::Isometry3d X =
          toIsometry(buffer_.lookupTransform(fixture().fixed_frame, link.name, stamp).transform);
      const Eigen::Isometry3d expected = body.initial_link_pose * link.pose_in_body_link;
      EXPECT_LE((X.translation() - expected.translation()).norm(), kTfTolerance) << link.name;
      EXPECT_LE((X.linear() - expected.linear()).cwiseAbs().maxCoeff(), kRotationTolerance) << link.name;
    }
  expectTfAgreesWithPositions(stamp, "initial");
}

TEST_F(Tf, AgreesWithPositionsAfterSetState)
{
  Vector6d brick, tet, roller;
  brick << 0.4, -0.7, 2.9, 0.3, -1.2, 2.5;
  tet << -1.1, kPi / 2 - 1e-9, 0.6, -0.5, 0.75, 1.25;  // near gimbal lock
  roller << 31.0, 1.2, -100.5, 2.0, 0.0, -0.5;         // angles far outside (-pi, pi]
  server().setState({ { "brick", brick }, { "tet", tet }, { "roller", roller } });
  // Any publication stamped after set_state returned carries the new state.
  expectTfAgreesWithPositions(waitForStampAfter("brick", ros::Time::now()), "after_set_state");

  // A second change, of one body only, shows up too.
  brick << -2.0, 0.3, 0.1, -0.25, 0.5, 0.125;
  server().setState("brick", brick);
  const ros::Time stamp = waitForStampAfter("brick", ros::Time::now());
  expectTfAgreesWithPositions(stamp, "after_second_set_state");
  const Eigen::Isometry3d X = toIsometry(buffer_.lookupTransform(fixture().fixed_frame, "brick", stamp).transform);
  EXPECT_LE((X.linear() - refRotation(brick[0], brick[1], brick[2])).cwiseAbs().maxCoeff(), kRotationTolerance);
}

TEST_F(Tf, StaticLinksOnTfStaticOnly)
{
  TfRecorder static_tf("/tf_static"), dynamic_tf("/tf");
  std::set<std::string> expected_static;
  for (const FixtureStaticLink& link : fixture().static_links)
    expected_static.insert(link.name);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
  while (ros::WallTime::now() < deadline &&
         (static_tf.frames() != expected_static || dynamic_tf.messages().size() < 5))
    ros::WallDuration(0.01).sleep();
  ros::WallDuration(0.2).sleep();  // anything else that was going to arrive

  EXPECT_EQ(static_tf.frames(), expected_static) << "/tf_static must carry exactly the static links";
  for (const tf2_msgs::TFMessage& message : static_tf.messages())
    for (const geometry_msgs::TransformStamped& t : message.transforms)
    {
      EXPECT_EQ(t.header.frame_id, fixture().fixed_frame);
      for (const FixtureStaticLink& link : fixture().static_links)
        if (link.name == t.child_frame_id)
        {
          const Eigen::Isometry3d X = toIsometry(t.transform);
          EXPECT_LE((X.translation() - link.pose.translation()).norm(), kTfTolerance) << link.name;
          EXPECT_LE((X.linear() - link.pose.linear()).cwiseAbs().maxCoeff(), kRotationTolerance) << link.name;
        }
    }
  // The buffer resolves them as well.
  for (const FixtureStaticLink& link : fixture().static_links)
  {
    const Eigen::Isometry3d X =
        toIsometry(buffer_.lookupTransform(fixture().fixed_frame, link.name, ros::Time(0), ros::Duration(kTimeout))
                       .transform);
    EXPECT_LE((X.translation() - link.pose.translation()).norm(), kTfTolerance) << link.name;
  }

  // /tf: every publication is one message with every body and merged link
  // frame, one stamp, parent fixed_frame, and no static link.
  std::set<std::string> expected_dynamic;
  for (const FixtureBody& body : fixture().bodies)
    for (const FixtureLink& link : body.links)
      expected_dynamic.insert(link.name);
  const std::vector<tf2_msgs::TFMessage> messages = dynamic_tf.messages();
  ASSERT_GE(messages.size(), 5u) << "~publish_rate is 50 Hz by default";
  for (const tf2_msgs::TFMessage& message : messages)
  {
    std::set<std::string> frames;
    for (const geometry_msgs::TransformStamped& t : message.transforms)
    {
      frames.insert(t.child_frame_id);
      EXPECT_EQ(t.header.frame_id, fixture().fixed_frame);
      EXPECT_EQ(t.header.stamp, message.transforms.front().header.stamp);
    }
    EXPECT_EQ(frames, expected_dynamic);
    EXPECT_EQ(message.transforms.size(), expected_dynamic.size());
  }
}

}  // namespace drb_rostest
