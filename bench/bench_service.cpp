// Service-level benchmark: a roscpp client with persistent ServiceClients
// (default sockets, then TCP_NODELAY for comparison) against the real
// rigid_body_server,
// started by scripts/bench with ~benchmark_services:=true on a scene of
// bodies "v<N>" with N vertices (bench/make_service_scene.py).
//
//   drb_bench_service services <out.json> [budget_s]
//   drb_bench_service tf_sink <out.json> <seconds>
//
// `services` times, per call (median and quartiles over repeated calls):
// ~ping; ~get_mass_matrix (one matrix, and K = 1000 configurations);
// for each body: ~get_vertex_jacobians, ~backprop and the reduced
// transports of ~get_vertex_jacobians_compact, and ~inverse_dynamics and
// ~forward_dynamics of one body (K = 1, and K = 1000 with derivatives), each next
// to ~echo moving the same number of payload bytes each way, plus the error of the reduced
// transports against the full answer. `tf_sink` subscribes to /tf and counts
// what arrives (the scene-scale benchmark uses it as the tf consumer).
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <utility>
#include <random>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>

#include <diff_rigid_body/Backprop.h>
#include <diff_rigid_body/Echo.h>
#include <diff_rigid_body/ForwardDynamics.h>
#include <diff_rigid_body/GetBodies.h>
#include <diff_rigid_body/GetMassMatrix.h>
#include <diff_rigid_body/GetVertexJacobians.h>
#include <diff_rigid_body/GetVertexJacobiansCompact.h>
#include <diff_rigid_body/InverseDynamics.h>
#include <diff_rigid_body/Ping.h>

#include "service_timing.h"

namespace
{
using drb_bench::caller;
using drb_bench::Clock;
using drb_bench::persistentClient;
using drb_bench::timeAgainstEcho;
using drb_bench::timePair;
using drb_bench::Timing;

/// roscpp's ServiceClient takes no TransportHints: set TCP_NODELAY on every
/// TCP socket of this (client-only) process instead. Returns how many.
int setNoDelayOnAllSockets()
{
  int count = 0;
  DIR* dir = opendir("/proc/self/fd");
  if (!dir)
    return 0;
  while (dirent* entry = readdir(dir))
  {
    const int fd = std::atoi(entry->d_name);
    if (fd <= 2)
      continue;
    int type = 0;
    socklen_t length = sizeof(type);
    sockaddr_storage address{};
    socklen_t address_length = sizeof(address);
    if (getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &length) != 0 || type != SOCK_STREAM)
      continue;
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&address), &address_length) != 0 ||
        (address.ss_family != AF_INET && address.ss_family != AF_INET6))
      continue;
    const int one = 1;
    if (setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one)) == 0)
      ++count;
  }
  closedir(dir);
  return count;
}

/// ~get_mass_matrix of one body against ~ping, then K = 1000 configurations against the same-size echo.
void timeMassMatrix(ros::ServiceClient& mass_client, diff_rigid_body::GetMassMatrix& mass,
                    ros::ServiceClient& ping_client, ros::ServiceClient& echo_client, double budget,
                    std::vector<Timing>& timings)
{
  diff_rigid_body::Ping ping;
  auto [m, p] = timePair("get_mass_matrix", caller(mass_client, mass), "ping", caller(ping_client, ping), budget);
  m.response_bytes = 36 * 8;
  timings.push_back(p);
  timings.push_back(m);

  diff_rigid_body::GetMassMatrix batch;
  batch.request.bodies = mass.request.bodies;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int i = 0; i < 6000; ++i)
    batch.request.q.push_back(u(rng));
  timeAgainstEcho("get_mass_matrix_K1000", caller(mass_client, batch), 6000, 37000, echo_client, budget, timings);
}

/// A reduced transport of ~get_vertex_jacobians_compact.
struct CompactVariant
{
  const char* name;
  bool positions_only, single_precision;
  std::size_t bytes_per_vertex;
};

/// JSON fields of a reduced transport's error against the full answer:
/// max |difference| / max |full value|, for the positions and the rotation block.
std::string compactErrors(const CompactVariant& v, const diff_rigid_body::GetVertexJacobians::Response& full,
                          const diff_rigid_body::GetVertexJacobiansCompact::Response& compact, std::size_t n)
{
  double pos_err = 0, pos_scale = 0, jac_err = 0, jac_scale = 0;
  for (std::size_t i = 0; i < 3 * n; ++i)
  {
    const double got = v.single_precision ? compact.positions_f32[i] : compact.positions[i];
    pos_err = std::max(pos_err, std::abs(got - full.positions[i]));
    pos_scale = std::max(pos_scale, std::abs(full.positions[i]));
  }
  if (!v.positions_only)
    for (std::size_t i = 0; i < n; ++i)
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k)
        {
          const double value = full.jacobians[18 * i + 6 * r + k];
          const double got = v.single_precision ? compact.rotation_jacobians_f32[9 * i + 3 * r + k]
                                                : compact.rotation_jacobians[9 * i + 3 * r + k];
          jac_err = std::max(jac_err, std::abs(got - value));
          jac_scale = std::max(jac_scale, std::abs(value));
        }
  char extra[160];
  std::snprintf(extra, sizeof(extra), "\"position_rel_error\": %.6g, \"jacobian_rel_error\": %.6g",
                pos_scale > 0 ? pos_err / pos_scale : 0.0, jac_scale > 0 ? jac_err / jac_scale : 0.0);
  return extra;
}

/// ~get_vertex_jacobians of one body with n vertices, then each reduced transport, each
/// against ~echo of its response's size.
void timeJacobians(ros::ServiceClient& jac_client, ros::ServiceClient& compact_client,
                   ros::ServiceClient& echo_client, const std::string& body, std::size_t n,
                   const std::vector<double>& q, double budget, std::vector<Timing>& timings)
{
  const std::string suffix = "/" + std::to_string(n);
  diff_rigid_body::GetVertexJacobians jac;
  jac.request.body = body;
  jac.request.q = q;
  timeAgainstEcho("get_vertex_jacobians" + suffix, caller(jac_client, jac), 0, 21 * n, echo_client, budget,
                  timings);
  const CompactVariant variants[] = { { "compact_rotation_block", false, false, 12 * 8 },
                                      { "compact_rotation_block_f32", false, true, 12 * 4 },
                                      { "compact_positions_only", true, false, 3 * 8 } };
  for (const CompactVariant& v : variants)
  {
    diff_rigid_body::GetVertexJacobiansCompact compact;
    compact.request.body = body;
    compact.request.q = q;
    compact.request.positions_only = v.positions_only;
    compact.request.single_precision = v.single_precision;
    diff_rigid_body::Echo echo;
    echo.request.response_size = static_cast<std::uint32_t>((v.bytes_per_vertex * n + 7) / 8);
    auto [c, e] = timePair(std::string(v.name) + suffix, caller(compact_client, compact),
                           std::string("echo_for_") + v.name + suffix, caller(echo_client, echo), budget);
    c.response_bytes = e.response_bytes = v.bytes_per_vertex * n;
    c.extra = compactErrors(v, jac.response, compact.response, n);
    timings.push_back(c);
    timings.push_back(e);
  }
}

/// ~backprop of one body with n vertices (normal random gradients) against the same-size echo.
void timeBackprop(ros::ServiceClient& bp_client, ros::ServiceClient& echo_client, const std::string& body,
                  std::size_t n, const std::vector<double>& q, double budget, std::vector<Timing>& timings)
{
  diff_rigid_body::Backprop bp;
  bp.request.body = body;
  bp.request.q = q;
  bp.request.gradients.resize(3 * n);
  std::mt19937_64 rng(n);
  std::normal_distribution<double> g(0.0, 1.0);
  for (double& x : bp.request.gradients)
    x = g(rng);
  timeAgainstEcho("backprop/" + std::to_string(n), caller(bp_client, bp), 3 * n, 6, echo_client, budget, timings);
}

/// ~inverse_dynamics and ~forward_dynamics of one free body (6 coordinates): K = 1 without
/// derivatives, K = 1000 with them; configurations with |theta| <= 1 (M regular).
void timeDynamics(ros::NodeHandle& nh, const std::string& ns, const std::string& body,
                  ros::ServiceClient& echo_client, double budget, std::vector<Timing>& timings)
{
  auto id_client = persistentClient<diff_rigid_body::InverseDynamics>(nh, ns + "inverse_dynamics");
  auto fd_client = persistentClient<diff_rigid_body::ForwardDynamics>(nh, ns + "forward_dynamics");
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto values = [&](std::size_t count) {
    std::vector<double> v(count);
    for (double& x : v)
      x = u(rng);
    return v;
  };
  for (const std::size_t K : { std::size_t(1), std::size_t(1000) })
  {
    const bool derivatives = K > 1;
    const std::string suffix = "/K" + std::to_string(K);
    diff_rigid_body::InverseDynamics id;
    id.request.bodies = { body };
    id.request.q = values(6 * K);
    id.request.qdot = values(6 * K);
    id.request.qddot = values(6 * K);
    id.request.derivatives = derivatives;
    // per configuration: tau, c, g (6 each), cos(theta); with derivatives dtau/dx, dtau/dx' (36 each)
    timeAgainstEcho("inverse_dynamics" + suffix, caller(id_client, id), 18 * K, (19 + (derivatives ? 72 : 0)) * K,
                    echo_client, budget, timings);
    diff_rigid_body::ForwardDynamics fd;
    fd.request.bodies = id.request.bodies;
    fd.request.q = id.request.q;
    fd.request.qdot = id.request.qdot;
    fd.request.tau = values(6 * K);
    fd.request.derivatives = derivatives;
    // per configuration: x'' (6), cos(theta); with derivatives dx''/dx, dx''/dx', M^-1 (36 each)
    timeAgainstEcho("forward_dynamics" + suffix, caller(fd_client, fd), 18 * K, (7 + (derivatives ? 108 : 0)) * K,
                    echo_client, budget, timings);
  }
}

int runServices(const std::string& out_path, double budget)
{
  ros::NodeHandle nh;
  const std::string ns = "/rigid_body_server/";
  auto bodies_client = persistentClient<diff_rigid_body::GetBodies>(nh, ns + "get_bodies");
  auto ping_client = persistentClient<diff_rigid_body::Ping>(nh, ns + "ping");
  auto echo_client = persistentClient<diff_rigid_body::Echo>(nh, ns + "echo");
  auto mass_client = persistentClient<diff_rigid_body::GetMassMatrix>(nh, ns + "get_mass_matrix");
  auto jac_client = persistentClient<diff_rigid_body::GetVertexJacobians>(nh, ns + "get_vertex_jacobians");
  auto compact_client =
      persistentClient<diff_rigid_body::GetVertexJacobiansCompact>(nh, ns + "get_vertex_jacobians_compact");
  auto bp_client = persistentClient<diff_rigid_body::Backprop>(nh, ns + "backprop");

  diff_rigid_body::GetBodies bodies;
  if (!bodies_client.call(bodies) || !bodies.response.success)
    throw std::runtime_error("get_bodies failed");

  // Everything with roscpp's default sockets first (what a roscpp client
  // gets), then ~ping and ~get_mass_matrix again with TCP_NODELAY.
  std::vector<Timing> timings;
  diff_rigid_body::GetMassMatrix mass;
  mass.request.bodies = { bodies.response.names.front() };
  mass.request.q = { 0.3, -0.2, 0.1, 1.0, 2.0, 3.0 };
  timeMassMatrix(mass_client, mass, ping_client, echo_client, budget, timings);
  const std::vector<double> q = { 0.3, -1.2, 2.5, 0.5, -0.25, 1.5 };
  for (std::size_t b = 0; b < bodies.response.names.size(); ++b)
  {
    const std::string& body = bodies.response.names[b];
    const std::size_t n = bodies.response.vertex_counts[b];
    const double body_budget = n >= 100000 ? std::max(budget, 1.0) : budget;
    timeJacobians(jac_client, compact_client, echo_client, body, n, q, body_budget, timings);
    timeBackprop(bp_client, echo_client, body, n, q, body_budget, timings);
    std::fprintf(stderr, "drb_bench_service: %s (%zu vertices) done\n", body.c_str(), n);
  }
  timeDynamics(nh, ns, bodies.response.names.front(), echo_client, budget, timings);

  const int sockets = setNoDelayOnAllSockets();
  std::fprintf(stderr, "drb_bench_service: TCP_NODELAY on %d sockets\n", sockets);
  diff_rigid_body::Ping ping;
  auto [m, p] = timePair("get_mass_matrix_nodelay", caller(mass_client, mass), "ping_nodelay",
                         caller(ping_client, ping), budget);
  m.response_bytes = 36 * 8;
  timings.push_back(p);
  timings.push_back(m);
  drb_bench::writeTimings(out_path, sockets, timings);
  return 0;
}

int runTfSink(const std::string& out_path, double seconds)
{
  ros::NodeHandle nh;
  std::size_t messages = 0, transforms = 0;
  ros::Subscriber sub = nh.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100,
      [&](const tf2_msgs::TFMessage::ConstPtr& m) {
        ++messages;
        transforms += m->transforms.size();
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  // Wait for the first message, then count for `seconds`.
  const auto deadline = Clock::now() + std::chrono::seconds(30);
  while (ros::ok() && messages == 0 && Clock::now() < deadline)
    ros::spinOnce(), ros::Duration(0.001).sleep();
  messages = transforms = 0;
  const auto start = Clock::now();
  while (ros::ok() && std::chrono::duration<double>(Clock::now() - start).count() < seconds)
    ros::spinOnce(), ros::Duration(0.0005).sleep();
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::FILE* out = std::fopen(out_path.c_str(), "w");
  if (!out)
    return 1;
  std::fprintf(out, "{\"seconds\": %.6g, \"messages\": %zu, \"transforms\": %zu}\n", elapsed, messages, transforms);
  std::fclose(out);
  return 0;
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "drb_bench_service", ros::init_options::AnonymousName);
  if (argc < 3)
  {
    std::fprintf(stderr, "usage: %s services <out.json> [budget_s] | tf_sink <out.json> <seconds>\n", argv[0]);
    return 2;
  }
  const std::string mode = argv[1];
  try
  {
    if (mode == "services")
      return runServices(argv[2], argc > 3 ? std::atof(argv[3]) : 0.5);
    if (mode == "tf_sink")
      return runTfSink(argv[2], argc > 3 ? std::atof(argv[3]) : 3.0);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "drb_bench_service: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
  return 2;
}
