#include "rigid_body_server.h"

#include "server_helpers.h"

#include <algorithm>
#include <cstring>

#include <geometry_msgs/TransformStamped.h>
#include <tf2_msgs/TFMessage.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/state/state_file.h"

namespace diff_rigid_body
{
using node::serve;
using node::serveAnswer;
using node::setTransform;

namespace
{
// The state to start from: the state file's when it holds a valid state of
// this scene, else the URDF's (an unusable file is set aside with a warning).
// The result is saved at once, so that an unwritable ~state_file stops the
// node at start (StateFileError) instead of refusing every later change.
SceneState initialState(const SceneQueries& queries, const std::string& state_file)
{
  SceneState state = queries.initialState();
  if (state_file.empty())
    return state;
  if (const std::size_t stale = removeStaleTemporaryFiles(state_file))
    ROS_INFO_STREAM("rigid_body_server: removed " << stale << " temporary file(s) of '" << state_file
                                                  << "' left by an interrupted save");
  try
  {
    if (std::optional<SceneState> saved = readStateFile(state_file, queries.scene()))
    {
      ROS_INFO_STREAM("rigid_body_server: resumed the state saved in '" << state_file << "'");
      return *saved;
    }
    ROS_INFO_STREAM("rigid_body_server: no state file '" << state_file << "' yet; starting from the URDF state");
  }
  catch (const StateFileError& e)
  {
    const std::string aside = setStateFileAside(state_file);
    ROS_WARN_STREAM("rigid_body_server: ignoring the state file: " << e.what() << "; starting from the URDF state"
                                                                   << (aside.empty() ? "" : "; the file was moved to '" +
                                                                                                aside + "'"));
  }
  writeStateFile(state_file, queries.scene(), state);
  return state;
}

std::vector<NamedState> toNamedStates(const std::vector<BodyState>& states)
{
  std::vector<NamedState> named;
  named.reserve(states.size());
  for (const BodyState& state : states)
    named.push_back(
        { state.name, Eigen::Map<const Eigen::VectorXd>(state.q.data(), static_cast<Eigen::Index>(state.q.size())) });
  return named;
}
}  // namespace

RigidBodyServer::RigidBodyServer(ros::NodeHandle& nh, ros::NodeHandle& private_nh, Scene scene,
                                 const ServerSettings& settings)
  : queries_(std::move(scene), settings.gravity)
  , state_file_(settings.state_file)
  , frame_prefix_(settings.frame_prefix)
  , state_(std::make_shared<const SceneState>(initialState(queries_, state_file_)))
  , joint_limit_warnings_(queries_.scene())
{
  tf_subscriber_counter_ = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);  // as tf2_ros::TransformBroadcaster
  states_publisher_ = private_nh.advertise<BodyStateArray>("states", 10, /*latch=*/true);
  initOutgoingMessages(*state_);
  publishStaticLinks();
  publishState(ros::Time::now(), /*state_changed=*/true);

  // Every service of the registry (the handler must take its srv type); the benchmark-only ones
  // with ~benchmark_services.
  const bool benchmark_services = private_nh.param("benchmark_services", false);
#define DRB_ADVERTISE(name, srv_type, handler, python_method, cpp_method, benchmark_only)                              \
  if (!(benchmark_only) || benchmark_services)                                                                         \
    services_.push_back(node::advertiseBounded<srv_type>(private_nh, #name, &RigidBodyServer::handler, this));
  DIFF_RIGID_BODY_SERVICES(DRB_ADVERTISE)
#undef DRB_ADVERTISE
  // After the services: a client that sees ~set_states subscribed sees every service.
  set_states_subscriber_ = private_nh.subscribe("set_states", 100, &RigidBodyServer::onSetStates, this,
                                                ros::TransportHints().tcpNoDelay());
  joint_states_subscriber_ = nh.subscribe("joint_states", 10, &RigidBodyServer::onJointStates, this);
  timer_ = private_nh.createTimer(ros::Duration(1.0 / settings.publish_rate), &RigidBodyServer::onTimer, this);
}

RigidBodyServer::StatePtr RigidBodyServer::snapshot() const
{
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return state_;
}

void RigidBodyServer::commit(const std::function<SceneState(const SceneState&)>& change, bool only_if_changed)
{
  std::lock_guard<std::mutex> write(write_mutex_);
  const StatePtr previous = snapshot();
  auto next = std::make_shared<const SceneState>(change(*previous));
  if (only_if_changed && *next == *previous)
    return;
  if (!state_file_.empty())
    writeStateFile(state_file_, queries_.scene(), *next);  // durable before it is visible or acknowledged
  {
    std::lock_guard<std::mutex> lock(snapshot_mutex_);
    state_ = next;
  }
  updateOutgoingMessages(*previous, *next);
  publishState(ros::Time::now(), /*state_changed=*/true);
  for (const std::string& warning : joint_limit_warnings_.check(*previous, *next))
    ROS_WARN_STREAM("rigid_body_server: " << warning);
}

void RigidBodyServer::applyStates(const std::vector<BodyState>& states)
{
  commit([&](const SceneState& current) { return queries_.applyStates(current, toNamedStates(states)); });
}

void RigidBodyServer::initOutgoingMessages(const SceneState& state)
{
  const Scene& scene = queries_.scene();
  first_transform_of_body_.assign(1, 0);
  for (const BodyModel& body : scene.bodies)
    first_transform_of_body_.push_back(first_transform_of_body_.back() + body.links.size());
  body_transforms_.resize(first_transform_of_body_.back());
  states_message_.header.frame_id = frame_prefix_ + scene.fixed_frame;
  states_message_.states.resize(scene.bodies.size());
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
  {
    const BodyModel& body = scene.bodies[i];
    for (std::size_t l = 0; l < body.links.size(); ++l)
    {
      geometry_msgs::TransformStamped& transform = body_transforms_[first_transform_of_body_[i] + l];
      transform.header.frame_id = frame_prefix_ + scene.fixed_frame;
      transform.child_frame_id = frame_prefix_ + body.links[l].name;
    }
    states_message_.states[i].name = body.name;
    writeBodyToOutgoingMessages(i, state[i]);
  }
}

void RigidBodyServer::updateOutgoingMessages(const SceneState& previous, const SceneState& next)
{
  for (std::size_t i = 0; i < next.size(); ++i)
    if (previous[i].size() != next[i].size() ||
        std::memcmp(previous[i].data(), next[i].data(), sizeof(double) * static_cast<std::size_t>(next[i].size())) != 0)
      writeBodyToOutgoingMessages(i, next[i]);
}

void RigidBodyServer::writeBodyToOutgoingMessages(std::size_t body_index, const Eigen::VectorXd& x)
{
  geometry_msgs::TransformStamped* transforms = &body_transforms_[first_transform_of_body_[body_index]];
  queries_.linkPoses(body_index, x, link_poses_);
  for (std::size_t l = 0; l < link_poses_.size(); ++l)
    setTransform(link_poses_[l], transforms[l].transform);
  states_message_.states[body_index].q.assign(x.data(), x.data() + x.size());
}

void RigidBodyServer::publishState(const ros::Time& stamp, bool state_changed)
{
  // Without a subscriber roscpp would drop the TFMessage unsent (see the header).
  if (tf_subscriber_counter_.getNumSubscribers() > 0)
  {
    for (geometry_msgs::TransformStamped& transform : body_transforms_)
      transform.header.stamp = stamp;
    tf_broadcaster_.sendTransform(body_transforms_);  // one TFMessage for all frames
  }
  // ~states is latched, so roscpp serialises every publication even without
  // a subscriber; an unchanged state is only re-sent to someone listening.
  if (state_changed || states_publisher_.getNumSubscribers() > 0)
  {
    states_message_.header.stamp = stamp;
    states_publisher_.publish(states_message_);
  }
}

void RigidBodyServer::publishStaticLinks()
{
  const Scene& scene = queries_.scene();
  if (scene.static_links.empty())
    return;
  std::vector<geometry_msgs::TransformStamped> transforms(scene.static_links.size());
  const ros::Time stamp = ros::Time::now();
  for (std::size_t i = 0; i < scene.static_links.size(); ++i)
  {
    transforms[i].header.stamp = stamp;
    transforms[i].header.frame_id = frame_prefix_ + scene.fixed_frame;
    transforms[i].child_frame_id = frame_prefix_ + scene.static_links[i].name;
    setTransform(scene.static_links[i].pose_in_fixed_frame, transforms[i].transform);
  }
  static_broadcaster_.sendTransform(transforms);
}

bool RigidBodyServer::setState(SetState::Request& request, SetState::Response& response)
{
  return serve(response, "set_state", [&] { applyStates(request.states); });
}

bool RigidBodyServer::getState(GetState::Request& request, GetState::Response& response)
{
  return serve(response, "get_state", [&] {
    for (const NamedState& named : queries_.getStates(*snapshot(), request.bodies))
    {
      BodyState state;
      state.name = named.name;
      state.q.assign(named.x.data(), named.x.data() + named.x.size());
      response.states.push_back(std::move(state));
    }
  });
}

void RigidBodyServer::onSetStates(const BodyStateArray::ConstPtr& message)
{
  const std::string failure = node::guardCallback("set_states", [&] { applyStates(message->states); });
  if (!failure.empty())
    ROS_WARN_STREAM_THROTTLE(1.0, "set_states: message dropped: " << failure);
}

void RigidBodyServer::onJointStates(const sensor_msgs::JointState::ConstPtr& message)
{
  const std::string failure = node::guardCallback("joint_states", [&] {
    commit([&](const SceneState& current) {
      std::vector<std::string> unknown;
      SceneState next = queries_.applyJointPositions(current, message->name, message->position, unknown);
      for (const std::string& name : unknown)  // under the writer mutex, which guards the set
        if (unknown_joints_logged_.size() < kMaxLoggedUnknownJoints && unknown_joints_logged_.insert(name).second)
          ROS_WARN_STREAM("joint_states: ignoring joint '" << name << "', which no body has (logged once)");
      return next;
    }, /*only_if_changed=*/true);  // a driver streaming an arm at rest costs no state-file write
  });
  if (!failure.empty())
    ROS_WARN_STREAM_THROTTLE(1.0, "joint_states: message dropped: " << failure);
}

void RigidBodyServer::onTimer(const ros::TimerEvent&)
{
  const std::string failure = node::guardCallback("the periodic publication", [&] {
    // Under the write lock, so a periodic message never goes out after (and
    // overrides) a newer state published by a writer.
    std::lock_guard<std::mutex> write(write_mutex_);
    publishState(ros::Time::now(), /*state_changed=*/false);
  });
  if (!failure.empty())
    ROS_ERROR_STREAM_THROTTLE(1.0, "rigid_body_server: " << failure);
}

void RigidBodyServer::prepare(GetFrameJacobians::Request& request) const
{
  node::removeFramePrefix(frame_prefix_, request.frames);  // "a/link" as tf names it, or "link"
}

void RigidBodyServer::present(BodiesAnswer& answer) const
{
  answer.fixed_frame = frame_prefix_ + answer.fixed_frame;
}

// The handlers of the services a core member answers (DRB_CORE_SERVICES, from each .srv's
// declaration): the member gets a snapshot of the state and the request's fields in the .srv's
// order (after prepare), and fills the answer that serveAnswer moves into the response (after
// present).
#define DRB_REQUEST_ARGUMENT(type, name) , request.name
#define DRB_SERVE_CORE(Type, name, handler, member, Answer)                                                            \
  bool RigidBodyServer::handler(Type::Request& request, Type::Response& response)                                      \
  {                                                                                                                    \
    return serveAnswer<Answer>(response, #name, [&](Answer& answer) {                                                  \
      prepare(request);                                                                                                \
      queries_.member(*snapshot() DRB_##Type##_REQUEST_FIELDS(DRB_REQUEST_ARGUMENT), answer);                          \
      present(answer);                                                                                                 \
    });                                                                                                                \
  }
DRB_CORE_SERVICES(DRB_SERVE_CORE)
#undef DRB_SERVE_CORE
#undef DRB_REQUEST_ARGUMENT

// ~ping and ~echo (benchmark only) measure transport (bench/).
bool RigidBodyServer::ping(Ping::Request&, Ping::Response& response)
{
  return serve(response, "ping", [] {});
}

bool RigidBodyServer::echo(Echo::Request& request, Echo::Response& response)
{
  return serve(response, "echo", [&] {
    if (request.response_size > 21 * RequestLimits::kMaxVertices)
      throw InvalidArgumentError("response_size: at most " + std::to_string(21 * RequestLimits::kMaxVertices));
    response.data.resize(request.response_size);
  });
}
}  // namespace diff_rigid_body
