// Load test of rigid_body_server (reliability_load.test): 8 concurrent
// clients for ~duration seconds, each mixing set_state, get_state,
// get_mass_matrix, get_vertex_jacobians and backprop through its own
// RigidBodyClient (the shipped C++ client: persistent connections).
//
// Every writer w writes, at its sequence number s, the full state
//   q(w, s, b) = (0.1 (w+1) + 0.01 b, 0.05 (w+1) + 0.001 b, 0.1 (w+1), w + 1, s, b)
// for every body b, so that a read that mixes two writes (a torn read) is
// detectable:
//   - get_state: body 0 names (w, s); every body must then equal q(w, s, b)
//     bit for bit;
//   - get_mass_matrix: each body's cos_theta names the writer; all bodies
//     must name the same one;
//   - get_vertex_jacobians: the positions must be R p0_i + t for the
//     rotation of one writer and a t naming (w, s) exactly;
//   - backprop: dL/dq must be that of one writer's rotation.
// The URDF initial state counts as writer "initial". At the end, every (w, s)
// read must have been acknowledged to its writer. Any failed call (transport
// or success=false) fails the test.
//
// The numbers (calls, p50/p99 latency overall and per service) are printed,
// recorded as JUnit properties and written to ~report_file when it is set.
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

using Vector6d = Eigen::Matrix<double, 6, 1>;
const char* const kServer = "/rigid_body_server";
const char* const kServices[] = { "set_state", "get_state", "get_mass_matrix", "get_vertex_jacobians", "backprop" };
constexpr int kServiceCount = 5;

Vector6d writtenQ(int w, long s, std::size_t b)
{
  Vector6d q;
  q << 0.1 * (w + 1) + 0.01 * b, 0.05 * (w + 1) + 0.001 * b, 0.1 * (w + 1), w + 1.0, static_cast<double>(s),
      static_cast<double>(b);
  return q;
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
  std::vector<std::string> names;
  std::vector<Vector6d> initial;      // URDF initial state per body
  std::vector<Eigen::Vector3d> p0;    // body 0's vertices in its body frame
  std::vector<Eigen::Vector3d> g;     // dL/dp for backprop on body 0, per vertex
  Eigen::Matrix3Xd gradients;         // the same, column i for vertex i
};

// One (writer, sequence) a reader saw.
struct Seen
{
  int w;
  long s;
};

struct ClientResult
{
  std::vector<double> latency[kServiceCount];  // s
  std::vector<Seen> seen;
  std::set<long> acked;  // this client's acknowledged sequence numbers
  std::vector<std::string> failures;
  std::vector<std::string> torn;
};

class Client
{
public:
  Client(int id, const SceneFacts& facts, std::atomic<bool>& stop)
    : id_(id), facts_(facts), stop_(stop), client_(ros::NodeHandle(), kServer, ros::Duration(60.0))
  {}

  void run()
  {
    for (long i = id_; !stop_.load(); ++i)
    {
      const int op = static_cast<int>(i % kServiceCount);
      const auto start = std::chrono::steady_clock::now();
      bool ok = false;
      switch (op)
      {
        case 0:
          ok = setState();
          break;
        case 1:
          ok = getState();
          break;
        case 2:
          ok = getMassMatrix();
          break;
        case 3:
          ok = getVertexJacobians();
          break;
        default:
          ok = backprop();
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

  void torn(const std::string& what) { result.torn.push_back("client " + std::to_string(id_) + ": " + what); }

  // The candidate state of body b for writer w (or the initial state).
  Vector6d candidate(int w, long s, std::size_t b) const
  {
    return w == kInitial ? facts_.initial[b] : writtenQ(w, s, b);
  }

  bool setState()
  {
    std::vector<std::pair<std::string, Vector6d>> states;
    for (std::size_t b = 0; b < facts_.names.size(); ++b)
      states.emplace_back(facts_.names[b], writtenQ(id_, sequence_, b));
    if (!call("set_state", [&] { client_.setState(states); }))
      return false;
    result.acked.insert(sequence_++);
    return true;
  }

  bool getState()
  {
    std::vector<std::pair<std::string, Vector6d>> states;
    if (!call("get_state", [&] { states = client_.getState(); }))
      return false;
    if (states.size() != facts_.names.size())
    {
      torn("get_state: " + std::to_string(states.size()) + " states");
      return true;
    }
    // Body 0 names the write; which is it?
    const Vector6d& q0 = states[0].second;
    int w = kInitial;
    long s = 0;
    if (std::memcmp(q0.data(), facts_.initial[0].data(), sizeof(double) * 6) != 0)
    {
      w = static_cast<int>(q0[3]) - 1;
      s = static_cast<long>(q0[4]);
      if (w < 0 || w >= kClients)
      {
        torn("get_state: body 0 names no writer (tx = " + std::to_string(q0[3]) + ")");
        return true;
      }
    }
    for (std::size_t b = 0; b < states.size(); ++b)
    {
      const Vector6d expected = candidate(w, s, b);
      if (states[b].first != facts_.names[b] ||
          std::memcmp(states[b].second.data(), expected.data(), sizeof(double) * 6))
      {
        std::ostringstream why;
        why.precision(17);
        why << "get_state: body " << b << " (" << states[b].first << ") is not part of write (" << w << ", " << s
            << "): q = [" << states[b].second.transpose() << "]";
        torn(why.str());
        return true;
      }
    }
    result.seen.push_back({ w, s });
    return true;
  }

  bool getMassMatrix()
  {
    std::vector<double> cos_theta;
    if (!call("get_mass_matrix", [&] { cos_theta = client_.massMatrices().cos_theta; }))
      return false;
    if (cos_theta.size() != facts_.names.size())
    {
      torn("get_mass_matrix: " + std::to_string(cos_theta.size()) + " matrices");
      return true;
    }
    // The writers whose theta every body's cos_theta fits (two writers may
    // share a theta for one body, never for all).
    std::set<int> writers;
    for (int w = kInitial; w < kClients; ++w)
      writers.insert(w);
    for (std::size_t b = 0; b < cos_theta.size(); ++b)
      for (int w = kInitial; w < kClients; ++w)
        if (std::abs(std::cos(candidate(w, 0, b)[1]) - cos_theta[b]) >= kCosTolerance)
          writers.erase(w);
    if (writers.empty())
      torn("get_mass_matrix: the bodies' cos_theta come from different writes");
    return true;
  }

  bool getVertexJacobians()
  {
    Eigen::Matrix3Xd positions;
    if (!call("get_vertex_jacobians", [&] { positions = client_.vertexJacobians(facts_.names[0]).positions; }))
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
        if ((t - facts_.initial[0].tail<3>()).norm() > kPositionTolerance)
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

  bool backprop()
  {
    Vector6d got;
    if (!call("backprop", [&] { got = client_.backprop(facts_.names[0], facts_.gradients); }))
      return false;
    for (int w = kInitial; w < kClients; ++w)
    {
      const Vector6d expected = drb_test::refBackprop(candidate(w, 0, 0), facts_.p0, facts_.g);
      if ((expected - got).cwiseAbs().maxCoeff() <= kGradientTolerance * std::max(1.0, expected.cwiseAbs().maxCoeff()))
        return true;
    }
    torn("backprop: dL/dq matches no written state");
    return true;
  }

  const int id_;
  const SceneFacts& facts_;
  std::atomic<bool>& stop_;
  long sequence_ = 0;
  RigidBodyClient client_;
};

SceneFacts learnScene()
{
  RigidBodyClient client(ros::NodeHandle(), kServer, ros::Duration(60.0));
  SceneFacts facts;
  for (const auto& [name, q] : client.getState())
  {
    facts.names.push_back(name);
    facts.initial.push_back(q);
  }
  // At q = 0 the positions are the body-frame vertices.
  const Eigen::Matrix3Xd p0 = client.vertexJacobians(facts.names.at(0), Vector6d::Zero()).positions;
  facts.gradients.resize(3, p0.cols());
  for (Eigen::Index i = 0; i < p0.cols(); ++i)
  {
    facts.p0.push_back(p0.col(i));
    facts.g.emplace_back(1.0 + i, -0.5 * i, 0.25);
    facts.gradients.col(i) = facts.g.back();
  }
  return facts;
}
}  // namespace

TEST(ReliabilityLoad, ConcurrentClientsSeeOnlyWholeAcknowledgedStates)
{
  ros::NodeHandle private_nh("~");
  const double duration = private_nh.param("duration", 10.0);  // s
  const std::string report_file = private_nh.param<std::string>("report_file", "");
  const SceneFacts facts = learnScene();
  ASSERT_GE(facts.names.size(), 2u) << "the torn-read check needs at least two bodies";

  std::atomic<bool> stop(false);
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

  // Gather.
  std::vector<double> all;
  std::vector<double> per_service[kServiceCount];
  std::size_t failures = 0, torn = 0, unacknowledged = 0, reads_checked = 0;
  for (int id = 0; id < kClients; ++id)
  {
    const ClientResult& result = clients[id]->result;
    for (int op = 0; op < kServiceCount; ++op)
    {
      per_service[op].insert(per_service[op].end(), result.latency[op].begin(), result.latency[op].end());
      all.insert(all.end(), result.latency[op].begin(), result.latency[op].end());
    }
    failures += result.failures.size();
    torn += result.torn.size();
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
  report << "all: p50 " << 1e3 * percentile(all, 0.50) << " ms, p99 " << 1e3 * percentile(all, 0.99) << " ms\n";
  for (int op = 0; op < kServiceCount; ++op)
    report << kServices[op] << ": calls " << per_service[op].size() << ", p50 " << 1e3 * percentile(per_service[op], 0.5)
           << " ms, p99 " << 1e3 * percentile(per_service[op], 0.99) << " ms\n";
  std::printf("%s", report.str().c_str());
  RecordProperty("calls", static_cast<int>(all.size()));
  RecordProperty("p50_ms", std::to_string(1e3 * percentile(all, 0.50)));
  RecordProperty("p99_ms", std::to_string(1e3 * percentile(all, 0.99)));
  if (!report_file.empty())
    std::ofstream(report_file) << report.str();

  EXPECT_EQ(failures, 0u);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(unacknowledged, 0u);
  // The test must have exercised every service, every writer, and seen reads of several writers.
  for (int op = 0; op < kServiceCount; ++op)
    EXPECT_GE(per_service[op].size(), 40u) << kServices[op];
  std::set<int> writers_seen;
  for (const auto& client : clients)
    for (const Seen& seen : client->result.seen)
      writers_seen.insert(seen.w);
  EXPECT_GE(writers_seen.size(), 3u) << "reads saw too few different writers to test interleaving";
}
