// Load test of rigid_body_server (reliability_load.test): 8 concurrent
// clients for ~duration seconds, each mixing set_state, get_state,
// get_mass_matrix (with dM/dx), get_vertex_jacobians, backprop and, when the
// node advertises them, inverse_dynamics and forward_dynamics (with their
// derivatives), each client through its own persistent connections (the
// shipped C++ RigidBodyClient). Meanwhile a publisher thread streams
// joint_states at ~joint_states_rate (1 kHz) for the joints of the scene's
// articulated bodies, so that joint_states commits interleave with set_state
// and the readers. scripts/sanitize_thread runs this test against a
// ThreadSanitizer build of the node.
//
// The free bodies (6 coordinates, no joint) are set_state's. Every writer w
// writes, at its sequence number s, the state
//   q(w, s, j) = (0.1 (w+1) + 0.01 j, 0.05 (w+1) + 0.001 j, 0.1 (w+1), w + 1, s, j)
// of every free body j (j-th free body), so that a read that mixes two writes
// (a torn read) is detectable:
//   - get_state: free body 0 names (w, s); every free body must then equal
//     q(w, s, j) bit for bit;
//   - get_mass_matrix, inverse_dynamics, forward_dynamics: each free body's
//     cos_theta names the writer; all free bodies must name the same one;
//   - get_vertex_jacobians: the positions must be R p0_i + t for the
//     rotation of one writer and a t naming (w, s) exactly;
//   - backprop: dL/dq must be that of one writer's rotation.
// The URDF initial state counts as writer "initial". At the end, every (w, s)
// read must have been acknowledged to its writer.
// The articulated bodies' joints are joint_states'. Message k sets every
// joint to a(k) = 0.25 + 0.0005 (k mod 1000) [rad or m]; get_state must show
// all joint coordinates at their initial values or all at one a(k) (a
// message applied whole), and the readers must see several messages' values.
// Any failed call (transport or success=false) fails the test.
//
// The numbers (calls, p50/p99 latency overall and per service, joint_states
// published) are printed, recorded as JUnit properties and written to
// ~report_file when it is set.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <diff_rigid_body/ForwardDynamics.h>
#include <diff_rigid_body/InverseDynamics.h>
#include <diff_rigid_body_ros/rigid_body_client.h>

#include "../support/kinematics_oracles.h"

using diff_rigid_body_ros::RigidBodyClient;

namespace
{
constexpr int kClients = 8;
constexpr int kInitial = -1;                  // "writer" of the URDF initial state
constexpr double kPositionTolerance = 1e-9;   // m
constexpr double kGradientTolerance = 1e-9;   // relative to max(1, |dL/dq|)
constexpr double kCosTolerance = 1e-12;
constexpr long kJointValues = 1000;           // joint_states cycles through a(0) .. a(999)

using Vector6d = Eigen::Matrix<double, 6, 1>;
const char* const kServer = "/rigid_body_server";
enum Op
{
  kSetState,
  kGetState,
  kGetMassMatrix,
  kGetVertexJacobians,
  kBackprop,
  kInverseDynamics,
  kForwardDynamics,
  kOpCount
};
const char* const kServices[kOpCount] = { "set_state", "get_state",        "get_mass_matrix", "get_vertex_jacobians",
                                          "backprop",  "inverse_dynamics", "forward_dynamics" };

Vector6d writtenQ(int w, long s, std::size_t j)
{
  Vector6d q;
  q << 0.1 * (w + 1) + 0.01 * j, 0.05 * (w + 1) + 0.001 * j, 0.1 * (w + 1), w + 1.0, static_cast<double>(s),
      static_cast<double>(j);
  return q;
}

/// The joint position of joint_states message k.
double jointValue(long k)
{
  return 0.25 + 0.0005 * static_cast<double>(k % kJointValues);
}

double percentile(std::vector<double> values, double p)
{
  if (values.empty())
    return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t index = std::min(values.size() - 1, static_cast<std::size_t>(std::ceil(p * values.size())) - 1);
  return values[index];
}

// What the test learned about the scene before the load starts.
struct SceneFacts
{
  std::vector<std::string> names;         // every body, in answer order
  std::vector<Eigen::VectorXd> initial;   // URDF initial state per body
  std::vector<std::size_t> free_bodies;   // bodies with 6 coordinates and no joint: set_state's
  std::vector<std::size_t> articulated;   // bodies with joints: joint_states'
  std::vector<std::size_t> joint_counts;  // per body: its joints, the last coordinates of its x
  std::vector<std::string> joint_names;   // the articulated bodies' joints
  std::vector<Eigen::Vector3d> p0;        // free body 0's vertices in its body frame
  std::vector<Eigen::Vector3d> g;         // dL/dp for backprop on free body 0, per vertex
  Eigen::Matrix3Xd gradients;             // the same, column i for vertex i
  bool dynamics = false;                  // inverse_dynamics and forward_dynamics advertised

  const std::string& freeName(std::size_t j) const { return names[free_bodies[j]]; }
};

// One (writer, sequence) a reader saw.
struct Seen
{
  int w;
  long s;
};

struct ClientResult
{
  std::vector<double> latency[kOpCount];  // s
  std::vector<Seen> seen;
  std::set<long> acked;        // this client's acknowledged sequence numbers
  std::set<long> joints_seen;  // joint_states messages (k mod kJointValues) read by get_state
  std::vector<std::string> failures;
  std::vector<std::string> torn;
};

class Client
{
public:
  Client(int id, const SceneFacts& facts, std::atomic<bool>& stop)
    : id_(id), facts_(facts), stop_(stop), client_(ros::NodeHandle(), kServer, ros::Duration(60.0))
  {
    if (facts_.dynamics)
      for (const Op op : ops_dynamics_)
        ops_.push_back(op);
  }

  void run()
  {
    for (long i = id_; !stop_.load(); ++i)
    {
      const Op op = ops_[static_cast<std::size_t>(i) % ops_.size()];
      const auto start = std::chrono::steady_clock::now();
      bool ok = false;
      switch (op)
      {
        case kSetState:
          ok = setState();
          break;
        case kGetState:
          ok = getState();
          break;
        case kGetMassMatrix:
          ok = getMassMatrix();
          break;
        case kGetVertexJacobians:
          ok = getVertexJacobians(i / static_cast<long>(ops_.size()));
          break;
        case kBackprop:
          ok = backprop();
          break;
        case kInverseDynamics:
          ok = inverseDynamics();
          break;
        default:
          ok = forwardDynamics();
          break;
      }
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      result.latency[op].push_back(seconds);
      if (!ok && result.failures.size() > 20)
        return;  // something is badly wrong; the test fails anyway
    }
  }

  ClientResult result;

private:
  /// Runs one call of the client; a refusal (success=false) or a transport
  /// failure is recorded as a failure.
  template <typename Call>
  bool call(const char* name, Call&& call)
  {
    try
    {
      call();
      return true;
    }
    catch (const diff_rigid_body_ros::ServiceError& e)
    {
      result.failures.push_back(std::string(name) + ": success=false: " + e.message());
    }
    catch (const diff_rigid_body_ros::ConnectionError& e)
    {
      result.failures.push_back(std::string(name) + ": transport failure: " + e.what());
    }
    return false;
  }

  /// A service that RigidBodyClient does not wrap (yet), on a persistent
  /// connection of this client's own, reconnected once on a transport failure.
  template <typename Service>
  void rawCall(ros::ServiceClient& client, const char* service, Service& srv)
  {
    const std::string name = std::string(kServer) + "/" + service;
    for (int attempt = 0; attempt < 2; ++attempt)
    {
      if (!client || !client.isValid())
        client = ros::NodeHandle().serviceClient<Service>(name, /*persistent=*/true);
      if (client.call(srv))
      {
        if (!srv.response.success)
          throw diff_rigid_body_ros::ServiceError(name, srv.response.message);
        return;
      }
      client.shutdown();
    }
    throw diff_rigid_body_ros::ConnectionError("service " + name + " failed after reconnecting");
  }

  void torn(const std::string& what) { result.torn.push_back("client " + std::to_string(id_) + ": " + what); }

  // The candidate state of free body j for writer w (or the initial state).
  Vector6d candidate(int w, long s, std::size_t j) const
  {
    return w == kInitial ? Vector6d(facts_.initial[facts_.free_bodies[j]]) : writtenQ(w, s, j);
  }

  bool setState()
  {
    std::vector<std::pair<std::string, Vector6d>> states;
    for (std::size_t j = 0; j < facts_.free_bodies.size(); ++j)
      states.emplace_back(facts_.freeName(j), writtenQ(id_, sequence_, j));
    if (!call("set_state", [&] { client_.setState(states); }))
      return false;
    result.acked.insert(sequence_++);
    return true;
  }

  bool getState()
  {
    std::vector<std::pair<std::string, Eigen::VectorXd>> states;
    if (!call("get_state", [&] { states = client_.getState(); }))
      return false;
    if (states.size() != facts_.names.size())
    {
      torn("get_state: " + std::to_string(states.size()) + " states");
      return true;
    }
    for (std::size_t b = 0; b < states.size(); ++b)
      if (states[b].first != facts_.names[b] || states[b].second.size() != facts_.initial[b].size())
      {
        torn("get_state: body " + std::to_string(b) + " is '" + states[b].first + "' with " +
             std::to_string(states[b].second.size()) + " coordinates");
        return true;
      }
    // Free body 0 names the write; which is it?
    const Eigen::VectorXd& q0 = states[facts_.free_bodies[0]].second;
    int w = kInitial;
    long s = 0;
    if (std::memcmp(q0.data(), facts_.initial[facts_.free_bodies[0]].data(), sizeof(double) * 6) != 0)
    {
      w = static_cast<int>(q0[3]) - 1;
      s = static_cast<long>(q0[4]);
      if (w < 0 || w >= kClients)
      {
        torn("get_state: free body 0 names no writer (tx = " + std::to_string(q0[3]) + ")");
        return true;
      }
    }
    for (std::size_t j = 0; j < facts_.free_bodies.size(); ++j)
    {
      const Eigen::VectorXd& q = states[facts_.free_bodies[j]].second;
      const Vector6d expected = candidate(w, s, j);
      if (std::memcmp(q.data(), expected.data(), sizeof(double) * 6))
      {
        std::ostringstream why;
        why.precision(17);
        why << "get_state: body " << facts_.free_bodies[j] << " (" << facts_.freeName(j)
            << ") is not part of write (" << w << ", " << s << "): q = [" << q.transpose() << "]";
        torn(why.str());
        return true;
      }
    }
    result.seen.push_back({ w, s });
    return checkJoints(states);
  }

  // The articulated bodies' joint coordinates: all initial, or all of one
  // joint_states message.
  bool checkJoints(const std::vector<std::pair<std::string, Eigen::VectorXd>>& states)
  {
    bool initial = true;
    long message = -1;
    bool one_message = true;
    for (std::size_t b : facts_.articulated)
    {
      const Eigen::VectorXd& x = states[b].second;
      const Eigen::Index first = x.size() - static_cast<Eigen::Index>(facts_.joint_counts[b]);
      for (Eigen::Index c = 0; c < x.size(); ++c)
      {
        if (std::memcmp(&x[c], &facts_.initial[b][c], sizeof(double)) != 0)
          initial = false;
        if (c < first)
          continue;  // a floating root's q: set_state's business, not joint_states'
        const long k = std::lround((x[c] - 0.25) / 0.0005);
        const double expected = jointValue(k);
        if (k < 0 || k >= kJointValues || std::memcmp(&x[c], &expected, sizeof(double)) != 0 ||
            (message >= 0 && k != message))
          one_message = false;
        message = k;
      }
    }
    if (facts_.articulated.empty() || initial)
      return true;
    if (!one_message)
    {
      std::ostringstream why;
      why.precision(17);
      why << "get_state: the joint coordinates are neither initial nor one joint_states message:";
      for (std::size_t b : facts_.articulated)
        why << " " << facts_.names[b] << " [" << states[b].second.transpose() << "]";
      torn(why.str());
      return true;
    }
    result.joints_seen.insert(message);
    return true;
  }

  /// cos_theta per body (one configuration): the free bodies' must all fit one writer.
  void checkCosTheta(const char* service, const std::vector<double>& cos_theta)
  {
    if (cos_theta.size() != facts_.names.size())
    {
      torn(std::string(service) + ": " + std::to_string(cos_theta.size()) + " cos_theta");
      return;
    }
    // The writers whose theta every free body's cos_theta fits (two writers
    // may share a theta for one body, never for all).
    std::set<int> writers;
    for (int w = kInitial; w < kClients; ++w)
      writers.insert(w);
    for (std::size_t j = 0; j < facts_.free_bodies.size(); ++j)
      for (int w = kInitial; w < kClients; ++w)
        if (std::abs(std::cos(candidate(w, 0, j)[1]) - cos_theta[facts_.free_bodies[j]]) >= kCosTolerance)
          writers.erase(w);
    if (writers.empty())
      torn(std::string(service) + ": the bodies' cos_theta come from different writes");
  }

  bool getMassMatrix()
  {
    diff_rigid_body_ros::MassMatrices answer;
    if (!call("get_mass_matrix", [&] { answer = client_.massMatrices({}, {}, /*derivatives=*/true); }))
      return false;
    if (answer.M.size() != facts_.names.size() || answer.dM.size() != facts_.names.size())
    {
      torn("get_mass_matrix: " + std::to_string(answer.M.size()) + " matrices, " + std::to_string(answer.dM.size()) +
           " derivatives");
      return true;
    }
    for (std::size_t b = 0; b < answer.M.size(); ++b)
      if (answer.M[b].rows() != facts_.initial[b].size() ||
          answer.dM[b].size() != static_cast<std::size_t>(facts_.initial[b].size()) || !answer.M[b].allFinite())
        torn("get_mass_matrix: body " + facts_.names[b] + ": matrix or dM/dx of the wrong size, or not finite");
    checkCosTheta("get_mass_matrix", answer.cos_theta);
    return true;
  }

  // Alternately free body 0 (checked against the writers) and an articulated
  // body (its per-thread kinematics workspace; checked for shape).
  bool getVertexJacobians(long round)
  {
    if (!facts_.articulated.empty() && round % 2 == 1)
      return getArticulatedVertexJacobians(facts_.articulated[static_cast<std::size_t>(round / 2) %
                                                              facts_.articulated.size()]);
    Eigen::Matrix3Xd positions;
    if (!call("get_vertex_jacobians", [&] { positions = client_.vertexJacobians(facts_.freeName(0)).positions; }))
      return false;
    if (static_cast<std::size_t>(positions.cols()) != facts_.p0.size())
    {
      torn("get_vertex_jacobians: " + std::to_string(positions.cols()) + " positions");
      return true;
    }
    const Eigen::Vector3d first = positions.col(0);
    for (int w = kInitial; w < kClients; ++w)
    {
      const Vector6d q = candidate(w, 0, 0);
      const Eigen::Matrix3d R = drb_test::refRotation(q[0], q[1], q[2]);
      const Eigen::Vector3d t = first - R * facts_.p0[0];
      long s = 0;
      if (w == kInitial)
      {
        if ((t - candidate(w, 0, 0).tail<3>()).norm() > kPositionTolerance)
          continue;
      }
      else
      {
        s = std::lround(t.y());
        if (std::abs(t.x() - (w + 1)) > kPositionTolerance || std::abs(t.y() - s) > kPositionTolerance ||
            std::abs(t.z()) > kPositionTolerance)
          continue;
      }
      const Eigen::Vector3d exact_t = candidate(w, s, 0).tail<3>();
      bool all = true;
      for (std::size_t i = 0; i < facts_.p0.size() && all; ++i)
        all = ((R * facts_.p0[i] + exact_t) - positions.col(i)).norm() <= kPositionTolerance;
      if (all)
      {
        result.seen.push_back({ w, s });
        return true;
      }
    }
    torn("get_vertex_jacobians: positions match no written state");
    return true;
  }

  bool getArticulatedVertexJacobians(std::size_t b)
  {
    diff_rigid_body_ros::VertexJacobians answer;
    if (!call("get_vertex_jacobians", [&] { answer = client_.vertexJacobians(facts_.names[b]); }))
      return false;
    if (answer.positions.cols() == 0 || answer.J.rows() != 3 * answer.positions.cols() ||
        answer.J.cols() != facts_.initial[b].size() || !answer.positions.allFinite() || !answer.J.allFinite())
      torn("get_vertex_jacobians: body " + facts_.names[b] + ": " + std::to_string(answer.positions.cols()) +
           " positions, J " + std::to_string(answer.J.rows()) + " x " + std::to_string(answer.J.cols()));
    return true;
  }

  bool backprop()
  {
    Eigen::VectorXd got;
    if (!call("backprop", [&] { got = client_.backprop(facts_.freeName(0), facts_.gradients); }))
      return false;
    if (got.size() != 6)
    {
      torn("backprop: " + std::to_string(got.size()) + " values");
      return true;
    }
    for (int w = kInitial; w < kClients; ++w)
    {
      const Vector6d expected = drb_test::refBackprop(candidate(w, 0, 0), facts_.p0, facts_.g);
      if ((expected - got).cwiseAbs().maxCoeff() <= kGradientTolerance * std::max(1.0, expected.cwiseAbs().maxCoeff()))
        return true;
    }
    torn("backprop: dL/dq matches no written state");
    return true;
  }

  std::size_t totalDofs() const
  {
    std::size_t total = 0;
    for (const Eigen::VectorXd& x : facts_.initial)
      total += static_cast<std::size_t>(x.size());
    return total;
  }

  std::size_t totalSquares() const
  {
    std::size_t total = 0;
    for (const Eigen::VectorXd& x : facts_.initial)
      total += static_cast<std::size_t>(x.size() * x.size());
    return total;
  }

  // The current state, every body, with C(x, x') and the derivatives.
  bool inverseDynamics()
  {
    diff_rigid_body::InverseDynamics srv;
    srv.request.coriolis_matrices = true;
    srv.request.derivatives = true;
    if (!call("inverse_dynamics", [&] { rawCall(inverse_dynamics_, "inverse_dynamics", srv); }))
      return false;
    const auto& r = srv.response;
    if (r.bodies != facts_.names || r.tau.size() != totalDofs() || r.gravity_terms.size() != totalDofs() ||
        r.coriolis_matrices.size() != totalSquares() || r.dtau_dq.size() != totalSquares() ||
        r.dtau_dqdot.size() != totalSquares() ||
        !std::all_of(r.tau.begin(), r.tau.end(), [](double v) { return std::isfinite(v); }))
      torn("inverse_dynamics: answer of the wrong shape or not finite");
    checkCosTheta("inverse_dynamics", r.cos_theta);
    return true;
  }

  bool forwardDynamics()
  {
    diff_rigid_body::ForwardDynamics srv;
    srv.request.derivatives = true;
    if (!call("forward_dynamics", [&] { rawCall(forward_dynamics_, "forward_dynamics", srv); }))
      return false;
    const auto& r = srv.response;
    if (r.bodies != facts_.names || r.qddot.size() != totalDofs() || r.dqddot_dq.size() != totalSquares() ||
        r.dqddot_dqdot.size() != totalSquares() || r.dqddot_dtau.size() != totalSquares() ||
        !std::all_of(r.qddot.begin(), r.qddot.end(), [](double v) { return std::isfinite(v); }))
      torn("forward_dynamics: answer of the wrong shape or not finite");
    checkCosTheta("forward_dynamics", r.cos_theta);
    return true;
  }

  const int id_;
  const SceneFacts& facts_;
  std::atomic<bool>& stop_;
  long sequence_ = 0;
  RigidBodyClient client_;
  ros::ServiceClient inverse_dynamics_, forward_dynamics_;
  std::vector<Op> ops_{ kSetState, kGetState, kGetMassMatrix, kGetVertexJacobians, kBackprop };
  const std::vector<Op> ops_dynamics_{ kInverseDynamics, kForwardDynamics };
};

SceneFacts learnScene()
{
  RigidBodyClient client(ros::NodeHandle(), kServer, ros::Duration(60.0));
  SceneFacts facts;
  for (const auto& [name, x] : client.getState())
  {
    facts.names.push_back(name);
    facts.initial.push_back(x);
  }
  const diff_rigid_body_ros::Bodies bodies = client.bodies();
  for (std::size_t b = 0; b < facts.names.size(); ++b)
  {
    const auto at = std::find(bodies.names.begin(), bodies.names.end(), facts.names[b]);
    const std::vector<std::string>& joints = bodies.joint_names.at(static_cast<std::size_t>(at - bodies.names.begin()));
    facts.joint_counts.push_back(joints.size());
    if (!joints.empty())
    {
      facts.articulated.push_back(b);
      facts.joint_names.insert(facts.joint_names.end(), joints.begin(), joints.end());
    }
    else if (facts.initial[b].size() == 6)
      facts.free_bodies.push_back(b);
  }
  if (facts.free_bodies.empty())
    return facts;
  // At q = 0 the positions are the body-frame vertices.
  const Eigen::Matrix3Xd p0 = client.vertexJacobians(facts.freeName(0), Vector6d::Zero()).positions;
  facts.gradients.resize(3, p0.cols());
  for (Eigen::Index i = 0; i < p0.cols(); ++i)
  {
    facts.p0.push_back(p0.col(i));
    facts.g.emplace_back(1.0 + i, -0.5 * i, 0.25);
    facts.gradients.col(i) = facts.g.back();
  }
  const std::string server(kServer);
  facts.dynamics = ros::service::exists(server + "/inverse_dynamics", false) &&
                   ros::service::exists(server + "/forward_dynamics", false);
  return facts;
}

struct Published
{
  long messages = 0;
  double seconds = 0.0;  // from the first message to the stop
};

/// Publishes joint_states (every articulated joint at jointValue(k) for
/// message k) at `rate` until `stop`, on a steady clock.
Published publishJointStates(const SceneFacts& facts, double rate, const std::atomic<bool>& stop)
{
  ros::Publisher publisher = ros::NodeHandle().advertise<sensor_msgs::JointState>("joint_states", 100);
  // The node must be subscribed before the load starts, or the first messages are lost.
  const auto subscribe_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (publisher.getNumSubscribers() == 0 && std::chrono::steady_clock::now() < subscribe_deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const auto period =
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1.0 / rate));
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  long k = 0;
  sensor_msgs::JointState message;
  message.name = facts.joint_names;
  message.position.resize(facts.joint_names.size());
  while (!stop.load())
  {
    std::fill(message.position.begin(), message.position.end(), jointValue(k));
    message.header.stamp = ros::Time::now();
    publisher.publish(message);
    ++k;
    next += period;
    const auto now = std::chrono::steady_clock::now();
    if (next < now - 100 * period)
      next = now;  // fell far behind (a stalled machine): no long burst to catch up
    std::this_thread::sleep_until(next);
  }
  return { k, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() };
}
}  // namespace

TEST(ReliabilityLoad, ConcurrentClientsSeeOnlyWholeAcknowledgedStates)
{
  ros::NodeHandle private_nh("~");
  const double duration = private_nh.param("duration", 10.0);                      // s
  const double joint_states_rate = private_nh.param("joint_states_rate", 1000.0);  // Hz, 0 = none
  const std::string report_file = private_nh.param<std::string>("report_file", "");
  const SceneFacts facts = learnScene();
  ASSERT_GE(facts.free_bodies.size(), 2u) << "the torn-read check needs at least two free bodies";
  const bool joint_states = joint_states_rate > 0.0 && !facts.joint_names.empty();

  std::atomic<bool> stop(false);
  Published published;
  std::thread joint_states_thread;
  if (joint_states)
    joint_states_thread = std::thread([&] { published = publishJointStates(facts, joint_states_rate, stop); });
  std::vector<std::unique_ptr<Client>> clients;
  for (int id = 0; id < kClients; ++id)
    clients.push_back(std::make_unique<Client>(id, facts, stop));
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  for (auto& client : clients)
    threads.emplace_back([&client] { client->run(); });
  std::this_thread::sleep_for(std::chrono::duration<double>(duration));
  stop = true;
  for (std::thread& thread : threads)
    thread.join();
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (joint_states_thread.joinable())
    joint_states_thread.join();

  // Gather.
  const int op_count = facts.dynamics ? kOpCount : kInverseDynamics;  // the dynamics services are the last two
  std::vector<double> all;
  std::vector<double> per_service[kOpCount];
  std::size_t failures = 0, torn = 0, unacknowledged = 0, reads_checked = 0;
  std::set<long> joints_seen;
  for (int id = 0; id < kClients; ++id)
  {
    const ClientResult& result = clients[id]->result;
    for (int op = 0; op < kOpCount; ++op)
    {
      per_service[op].insert(per_service[op].end(), result.latency[op].begin(), result.latency[op].end());
      all.insert(all.end(), result.latency[op].begin(), result.latency[op].end());
    }
    failures += result.failures.size();
    torn += result.torn.size();
    joints_seen.insert(result.joints_seen.begin(), result.joints_seen.end());
    for (const std::string& failure : result.failures)
      ADD_FAILURE() << "client " << id << ": " << failure;
    for (const std::string& what : result.torn)
      ADD_FAILURE() << what;
    for (const Seen& seen : result.seen)
    {
      ++reads_checked;
      if (seen.w != kInitial && !clients.at(seen.w)->result.acked.count(seen.s))
      {
        ++unacknowledged;
        ADD_FAILURE() << "client " << id << " read write (" << seen.w << ", " << seen.s
                      << "), which was never acknowledged";
      }
    }
  }

  std::ostringstream report;
  report.setf(std::ios::fixed);
  report.precision(3);
  report << "clients " << kClients << ", duration " << elapsed << " s, calls " << all.size() << " ("
         << all.size() / elapsed << " per s), failed " << failures << ", torn " << torn << ", unacknowledged reads "
         << unacknowledged << ", reads checked " << reads_checked << "\n";
  const double joint_states_per_second = published.seconds > 0.0 ? published.messages / published.seconds : 0.0;
  report << "joint_states: " << facts.joint_names.size() << " joint(s), published " << published.messages << " in "
         << published.seconds << " s (" << joint_states_per_second << " per s), distinct messages read back "
         << joints_seen.size() << "\n";
  report << "all: p50 " << 1e3 * percentile(all, 0.50) << " ms, p99 " << 1e3 * percentile(all, 0.99) << " ms\n";
  for (int op = 0; op < op_count; ++op)
    report << kServices[op] << ": calls " << per_service[op].size() << ", p50 " << 1e3 * percentile(per_service[op], 0.5)
           << " ms, p99 " << 1e3 * percentile(per_service[op], 0.99) << " ms\n";
  std::printf("%s", report.str().c_str());
  RecordProperty("calls", static_cast<int>(all.size()));
  RecordProperty("p50_ms", std::to_string(1e3 * percentile(all, 0.50)));
  RecordProperty("p99_ms", std::to_string(1e3 * percentile(all, 0.99)));
  RecordProperty("joint_states_published", static_cast<int>(published.messages));
  RecordProperty("joint_states_per_s", std::to_string(joint_states_per_second));
  RecordProperty("joint_states_read_back", static_cast<int>(joints_seen.size()));
  if (!report_file.empty())
    std::ofstream(report_file) << report.str();

  EXPECT_EQ(failures, 0u);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(unacknowledged, 0u);
  // The test must have exercised every service, every writer, and seen reads of several writers.
  for (int op = 0; op < op_count; ++op)
    EXPECT_GE(per_service[op].size(), 40u) << kServices[op];
  std::set<int> writers_seen;
  for (const auto& client : clients)
    for (const Seen& seen : client->result.seen)
      writers_seen.insert(seen.w);
  EXPECT_GE(writers_seen.size(), 3u) << "reads saw too few different writers to test interleaving";
  if (joint_states)
  {
    // At least half the asked rate (a loaded machine), and several messages' values read back.
    EXPECT_GE(published.messages, static_cast<long>(0.5 * joint_states_rate * duration));
    EXPECT_GE(joints_seen.size(), 3u) << "reads saw too few joint_states messages to test interleaving";
  }
}
