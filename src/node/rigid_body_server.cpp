#include "rigid_body_server.h"

#include "bounded_request.h"

#include <algorithm>
#include <cstring>

#include <geometry_msgs/TransformStamped.h>
#include <tf2_msgs/TFMessage.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/state_file.h"

namespace diff_rigid_body
{
namespace
{
// `pose` as a tf transform: its translation [m], and its rotation as a unit
// quaternion (x, y, z, w).
void setTransform(const Eigen::Isometry3d& pose, geometry_msgs::Transform& transform)
{
  transform.translation.x = pose.translation().x();
  transform.translation.y = pose.translation().y();
  transform.translation.z = pose.translation().z();
  const Eigen::Quaterniond rotation(pose.linear());
  transform.rotation.x = rotation.x();
  transform.rotation.y = rotation.y();
  transform.rotation.z = rotation.z();
  transform.rotation.w = rotation.w();
}

// Runs `work`; a core error becomes success=false with its message, so that
// the client receives it and nothing else happens. Returns true for roscpp.
template <typename Response, typename Work>
bool serve(Response& response, const char* service, Work&& work)
{
  try
  {
    work();
    response.success = true;
    response.message = "";
  }
  catch (const Error& e)
  {
    response = Response();
    response.success = false;
    response.message = e.what();
    ROS_DEBUG_STREAM(service << ": refused: " << e.what());
  }
  catch (const std::exception& e)  // e.g. std::bad_alloc: report, keep serving
  {
    response = Response();
    response.success = false;
    response.message = std::string("internal error: ") + e.what();
    ROS_ERROR_STREAM(service << ": " << response.message);
  }
  return true;
}

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

// Appends `matrix` row-major to `out`.
template <typename Matrix>
void appendMatrix(const Matrix& matrix, std::vector<double>& out)
{
  for (Eigen::Index r = 0; r < matrix.rows(); ++r)
    for (Eigen::Index c = 0; c < matrix.cols(); ++c)
      out.push_back(matrix(r, c));
}

// Advertises `handler` for the service Srv with bounded request decoding
// (bounded_request.h): a request refused there gets success=false and the
// refusal, and never reaches the handler.
template <typename Srv, typename Server>
ros::ServiceServer advertiseBounded(ros::NodeHandle& nh, const std::string& name,
                                    bool (Server::*handler)(typename Srv::Request&, typename Srv::Response&),
                                    Server* server)
{
  using Bounded = BoundedRequest<typename Srv::Request>;
  using Response = typename Srv::Response;
  const boost::function<bool(Bounded&, Response&)> callback = [server, handler, name](Bounded& bounded,
                                                                                      Response& response) {
    if (bounded.refusal.empty())
      return (server->*handler)(bounded.request, response);
    response = Response();
    response.success = false;
    response.message = bounded.refusal;
    ROS_DEBUG_STREAM(name << ": refused: " << bounded.refusal);
    return true;
  };
  return nh.advertiseService<Bounded, Response>(name, callback);
}

std::vector<NamedState> toNamedStates(const std::vector<BodyState>& states)
{
  std::vector<NamedState> named;
  named.reserve(states.size());
  for (const BodyState& state : states)
    named.push_back({ state.name, Eigen::Map<const Vector6<double>>(state.q.data()) });
  return named;
}
}  // namespace

RigidBodyServer::RigidBodyServer(ros::NodeHandle& nh, ros::NodeHandle& private_nh, Scene scene,
                                 const ServerSettings& settings)
  : queries_(std::move(scene))
  , state_file_(settings.state_file)
  , frame_prefix_(settings.frame_prefix)
  , state_(std::make_shared<const SceneState>(initialState(queries_, state_file_)))
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
    services_.push_back(advertiseBounded<srv_type>(private_nh, #name, &RigidBodyServer::handler, this));
  DIFF_RIGID_BODY_SERVICES(DRB_ADVERTISE)
#undef DRB_ADVERTISE
  // After the services: a client that sees ~set_states subscribed sees every service.
  set_states_subscriber_ = private_nh.subscribe("set_states", 100, &RigidBodyServer::onSetStates, this,
                                                ros::TransportHints().tcpNoDelay());
  timer_ = private_nh.createTimer(ros::Duration(1.0 / settings.publish_rate), &RigidBodyServer::onTimer, this);
}

RigidBodyServer::StatePtr RigidBodyServer::snapshot() const
{
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return state_;
}

void RigidBodyServer::applyStates(const std::vector<BodyState>& states)
{
  std::lock_guard<std::mutex> write(write_mutex_);
  const StatePtr previous = snapshot();
  auto next = std::make_shared<const SceneState>(queries_.applyStates(*previous, toNamedStates(states)));
  if (!state_file_.empty())
    writeStateFile(state_file_, queries_.scene(), *next);  // durable before it is visible or acknowledged
  {
    std::lock_guard<std::mutex> lock(snapshot_mutex_);
    state_ = next;
  }
  updateOutgoingMessages(*previous, *next);
  publishState(ros::Time::now(), /*state_changed=*/true);
}

void RigidBodyServer::initOutgoingMessages(const SceneState& state)
{
  const Scene& scene = queries_.scene();
  first_transform_of_body_.assign(1, 0);
  for (const SceneBody& body : scene.bodies)
    first_transform_of_body_.push_back(first_transform_of_body_.back() + body.links.size());
  body_transforms_.resize(first_transform_of_body_.back());
  states_message_.header.frame_id = frame_prefix_ + scene.fixed_frame;
  states_message_.states.resize(scene.bodies.size());
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
  {
    const SceneBody& body = scene.bodies[i];
    for (std::size_t l = 0; l < body.links.size(); ++l)
    {
      geometry_msgs::TransformStamped& transform = body_transforms_[first_transform_of_body_[i] + l];
      transform.header.frame_id = frame_prefix_ + scene.fixed_frame;
      transform.child_frame_id = frame_prefix_ + body.links[l].name;
    }
    states_message_.states[i].name = body.body.name;
    writeBodyToOutgoingMessages(i, state[i]);
  }
}

void RigidBodyServer::updateOutgoingMessages(const SceneState& previous, const SceneState& next)
{
  for (std::size_t i = 0; i < next.size(); ++i)
    if (std::memcmp(previous[i].data(), next[i].data(), sizeof(double) * 6) != 0)
      writeBodyToOutgoingMessages(i, next[i]);
}

void RigidBodyServer::writeBodyToOutgoingMessages(std::size_t body_index, const Vector6<double>& q)
{
  const SceneBody& body = queries_.scene().bodies[body_index];
  // Link l of the body: X_fixed_link = X_fixed_bodylink(q) * X_bodylink_link.
  const Eigen::Isometry3d link_pose = linkPoseFromState(q, body.body.com_offset);
  for (std::size_t l = 0; l < body.links.size(); ++l)
    setTransform(link_pose * body.links[l].pose_in_body_link,
                 body_transforms_[first_transform_of_body_[body_index] + l].transform);
  std::copy(q.data(), q.data() + 6, states_message_.states[body_index].q.begin());
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

bool RigidBodyServer::getBodies(GetBodies::Request&, GetBodies::Response& response)
{
  return serve(response, "get_bodies", [&] {
    response.fixed_frame = frame_prefix_ + queries_.scene().fixed_frame;
    for (const SceneBody& scene_body : queries_.scene().bodies)
    {
      const RigidBody& body = scene_body.body;
      response.names.push_back(body.name);
      response.masses.push_back(body.mass);
      appendMatrix(body.inertia_body, response.inertias);
      appendMatrix(body.com_offset, response.com_offsets);
      response.vertex_counts.push_back(static_cast<std::uint32_t>(body.vertices.cols()));
      response.dofs.push_back(6);
      response.joint_counts.push_back(0);
      response.link_counts.push_back(static_cast<std::uint32_t>(scene_body.links.size()));
      for (const LinkInBody& link : scene_body.links)
      {
        response.link_names.push_back(link.name);
        response.link_vertex_counts.push_back(link.new_vertex_count);
        response.link_masses.push_back(link.mass_properties.mass);
        appendMatrix(link.mass_properties.inertia, response.link_inertias);
        appendMatrix(link.mass_properties.com, response.link_com_offsets);
      }
    }
  });
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
      std::copy(named.q.data(), named.q.data() + 6, state.q.begin());
      response.states.push_back(std::move(state));
    }
  });
}

bool RigidBodyServer::getMassMatrix(GetMassMatrix::Request& request, GetMassMatrix::Response& response)
{
  return serve(response, "get_mass_matrix", [&] {
    MassMatrixAnswer answer = queries_.massMatrices(*snapshot(), request.bodies, request.q, request.derivatives);
    response.bodies = std::move(answer.bodies);
    response.mass_matrices = std::move(answer.mass_matrices);
    response.derivatives = std::move(answer.derivatives);
    response.cos_theta = std::move(answer.cos_theta);
  });
}

bool RigidBodyServer::getVertexJacobians(GetVertexJacobians::Request& request,
                                         GetVertexJacobians::Response& response)
{
  return serve(response, "get_vertex_jacobians", [&] {
    queries_.vertexJacobians(*snapshot(), request.body, request.vertices, request.q, response.positions,
                             response.jacobians);
  });
}

bool RigidBodyServer::backprop(Backprop::Request& request, Backprop::Response& response)
{
  return serve(response, "backprop", [&] {
    response.gradient =
        queries_.backpropConfigurations(*snapshot(), request.body, request.vertices, request.gradients, request.q);
  });
}

void RigidBodyServer::onSetStates(const BodyStateArray::ConstPtr& message)
{
  try
  {
    applyStates(message->states);
  }
  catch (const Error& e)
  {
    ROS_WARN_STREAM_THROTTLE(1.0, "set_states: message dropped: " << e.what());
  }
}

void RigidBodyServer::onTimer(const ros::TimerEvent&)
{
  // Under the write lock, so a periodic message never goes out after (and
  // overrides) a newer state published by a writer.
  std::lock_guard<std::mutex> write(write_mutex_);
  publishState(ros::Time::now(), /*state_changed=*/false);
}

// Reduced transport of get_vertex_jacobians; ~ping and ~echo (benchmark only) measure transport (bench/).
bool RigidBodyServer::getVertexJacobiansCompact(GetVertexJacobiansCompact::Request& request,
                                                GetVertexJacobiansCompact::Response& response)
{
  return serve(response, "get_vertex_jacobians_compact", [&] {
    if (request.single_precision)
      queries_.vertexRotationJacobians(*snapshot(), request.body, request.vertices, request.q, request.positions_only,
                                       response.positions_f32, response.rotation_jacobians_f32);
    else
      queries_.vertexRotationJacobians(*snapshot(), request.body, request.vertices, request.q, request.positions_only,
                                       response.positions, response.rotation_jacobians);
  });
}

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
