// rigid_body_server: the ROS layer over the core library.
//
// Messages in, core calls (SceneQueries), messages out. Core exceptions are
// caught at this boundary and become `success=false, message=...`; the
// callbacks always return true so that clients receive the message.
//
// Concurrency: the state is an immutable snapshot behind a shared_ptr.
// Readers take the current pointer under a short lock and compute without
// locks, so every answer comes from one consistent state; writers are
// serialised by a second mutex and swap in a new snapshot.
//
// Durable state (~state_file): a writer saves the new state (temp file,
// fsync, rename, fsync of the folder) before it swaps the snapshot in, so an
// acknowledged change survives a crash; a failed save refuses the change.
//
// Publication (tf and ~states) happens under the writer mutex, at
// ~publish_rate and after every accepted change, from messages kept equal to
// the current state: frame ids and names are written once at start, a state
// change rewrites the entries of the bodies whose x changed, and a periodic
// tick only restamps. A tick therefore costs O(links) stores plus what
// tf2_ros and roscpp do with the messages, with no quaternion or string work.
// roscpp drops a non-latched message that has no subscriber, so a tick skips
// /tf (the restamp and tf2_ros's copy into a TFMessage) while /tf has no
// subscriber: the traffic is the same, and a new subscriber gets the next tick.
//
// State changes come from set_state, ~set_states and joint_states
// (sensor_msgs/JointState, as robot_state_publisher reads it): each goes
// through commit(), so each is validated whole, saved, swapped in and
// published the same way, and a joint it puts outside its URDF limits is
// warned about once (joint_limit_warnings.h).
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>

#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <diff_rigid_body/BodyStateArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/JointState.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body_ros/services.h"
#include "joint_limit_warnings.h"

namespace diff_rigid_body
{
/// Node settings, read once from the private namespace.
struct ServerSettings
{
  double publish_rate = 50.0;  ///< [Hz] tf and ~states, clamped to [0.1, 1000]
  /// ~state_file: "" (off), or a file that every accepted state change is
  /// written to durably before it is acknowledged, and resumed from on start.
  std::string state_file;
  /// ~frame_prefix: prepended to every frame id the node publishes or
  /// reports (tf parent and child, /tf_static, ~states, get_bodies), as
  /// robot_state_publisher's frame_prefix; "" by default.
  std::string frame_prefix;
  /// ~gravity: gamma in the fixed frame [m/s^2], for the dynamics services.
  Eigen::Vector3d gravity = standardGravity();
};

class RigidBodyServer
{
public:
  /// Takes a loaded scene and starts serving on `private_nh`.
  RigidBodyServer(ros::NodeHandle& nh, ros::NodeHandle& private_nh, Scene scene, const ServerSettings& settings);

private:
  using StatePtr = std::shared_ptr<const SceneState>;

  StatePtr snapshot() const;
  /// Under the writer mutex: next = change(current) (throws to refuse, all
  /// or nothing), saved to ~state_file if set, swapped in, then published.
  /// With only_if_changed, a next equal to the current state is dropped.
  void commit(const std::function<SceneState(const SceneState&)>& change, bool only_if_changed = false);
  /// Validates and applies named states (all or nothing), then publishes them.
  void applyStates(const std::vector<BodyState>& states);
  /// Writes the frame ids and names of the outgoing messages, and their
  /// transforms and x from `state` (once, at start).
  void initOutgoingMessages(const SceneState& state);
  /// Rewrites the transforms and x of the bodies whose x differs (bitwise)
  /// between `previous` and `next`.
  void updateOutgoingMessages(const SceneState& previous, const SceneState& next);
  /// Body i's link frames from x (SceneQueries::linkPoses) and its x.
  void writeBodyToOutgoingMessages(std::size_t body_index, const Eigen::VectorXd& x);
  /// Restamps the outgoing messages and publishes them: all body link frames
  /// on /tf in one message (when /tf has a subscriber), and the states on
  /// ~states. Without a ~states subscriber, ~states goes out only if
  /// `state_changed`; its latched message then still holds the current state
  /// (every change is published), stamped at or after that change.
  void publishState(const ros::Time& stamp, bool state_changed);
  void publishStaticLinks();

  // The service handlers, one per entry of DIFF_RIGID_BODY_SERVICES (diff_rigid_body_ros/services.h).
#define DRB_DECLARE_HANDLER(name, srv_type, handler, python_method, cpp_method, benchmark_only)                        \
  bool handler(srv_type::Request& request, srv_type::Response& response);
  DIFF_RIGID_BODY_SERVICES(DRB_DECLARE_HANDLER)
#undef DRB_DECLARE_HANDLER
  /// What the node does to a request before the core member of its service (DRB_CORE_SERVICES)
  /// sees it: nothing, but for the frames of get_frame_jacobians, named as tf names them.
  template <typename Request>
  void prepare(Request&) const
  {
  }
  void prepare(GetFrameJacobians::Request& request) const;
  /// What the node does to a core member's answer before it is sent: nothing, but get_bodies'
  /// fixed_frame gets ~frame_prefix, as every frame id the node publishes.
  template <typename Answer>
  void present(Answer&) const
  {
  }
  void present(BodiesAnswer& answer) const;
  void onSetStates(const BodyStateArray::ConstPtr& message);
  /// joint_states: named joints set, unknown names ignored (each logged
  /// once), a message with a non-finite position, a position count other
  /// than the name count, or overflowing link poses dropped whole with a
  /// warning; a message that changes nothing is not committed.
  void onJointStates(const sensor_msgs::JointState::ConstPtr& message);
  void onTimer(const ros::TimerEvent& event);

  const SceneQueries queries_;
  const std::string state_file_;       ///< "" when durable state is off
  const std::string frame_prefix_;     ///< ~frame_prefix
  mutable std::mutex snapshot_mutex_;  ///< guards state_ (the pointer, not the data)
  std::mutex write_mutex_;             ///< serialises state changes and their publication
  StatePtr state_;

  // The outgoing messages, equal to *state_ and guarded by write_mutex_.
  /// Every link of every body, in body order, then link order within a body.
  std::vector<geometry_msgs::TransformStamped> body_transforms_;
  /// Body i's links are body_transforms_[first_transform_of_body_[i], first_transform_of_body_[i + 1]).
  std::vector<std::size_t> first_transform_of_body_;
  BodyStateArray states_message_;
  std::vector<Eigen::Isometry3d> link_poses_;  ///< scratch of writeBodyToOutgoingMessages

  tf2_ros::TransformBroadcaster tf_broadcaster_;
  /// A second handle on the broadcaster's /tf publication (roscpp keeps one
  /// publication per topic and process), used only for getNumSubscribers().
  ros::Publisher tf_subscriber_counter_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  ros::Publisher states_publisher_;
  ros::Subscriber set_states_subscriber_;
  ros::Subscriber joint_states_subscriber_;
  /// Joints of accepted states outside their URDF limits, warned once each (guarded by write_mutex_).
  JointLimitWarnings joint_limit_warnings_;
  /// Unknown joint names already logged (guarded by write_mutex_).
  std::set<std::string> unknown_joints_logged_;
  /// Distinct unknown joint names logged at most (a hostile publisher cannot grow the set).
  static constexpr std::size_t kMaxLoggedUnknownJoints = 1000;
  std::vector<ros::ServiceServer> services_;
  ros::Timer timer_;
};

}  // namespace diff_rigid_body
