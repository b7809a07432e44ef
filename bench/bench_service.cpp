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

namespace
{
using Clock = std::chrono::steady_clock;

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

struct Timing
{
  std::string name;
  std::size_t calls = 0;
  double median = 0, p25 = 0, p75 = 0, min = 0;  // seconds per call
  std::size_t request_bytes = 0, response_bytes = 0;  // payload (array data)
  std::string extra;  // additional JSON fields
};

/// Times two calls alternately (A, B, A, B, ...), so that both see the same
/// machine load: the ratio A / B is what the report uses.
std::pair<Timing, Timing> timePair(const std::string& name_a, const std::function<bool()>& a,
                                   const std::string& name_b, const std::function<bool()>& b, double budget)
{
  for (int i = 0; i < 3; ++i)
    if (!a() || !b())
      throw std::runtime_error(name_a + " / " + name_b + ": call failed");
  std::vector<double> runs_a, runs_b;
  const auto start = Clock::now();
  while (runs_a.size() < 5 ||
         (std::chrono::duration<double>(Clock::now() - start).count() < 2 * budget && runs_a.size() < 20000))
  {
    for (int which = 0; which < 2; ++which)
    {
      const auto t0 = Clock::now();
      if (!(which == 0 ? a() : b()))
        throw std::runtime_error((which == 0 ? name_a : name_b) + ": call failed");
      (which == 0 ? runs_a : runs_b).push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
  }
  auto summarise = [](const std::string& name, std::vector<double>& runs) {
    Timing t;
    t.name = name;
    std::sort(runs.begin(), runs.end());
    t.calls = runs.size();
    t.min = runs.front();
    t.median = runs[runs.size() / 2];
    t.p25 = runs[runs.size() / 4];
    t.p75 = runs[(3 * runs.size()) / 4];
    return t;
  };
  return { summarise(name_a, runs_a), summarise(name_b, runs_b) };
}

template <typename Service>
ros::ServiceClient persistentClient(ros::NodeHandle& nh, const std::string& name)
{
  if (!ros::service::waitForService(name, ros::Duration(60.0)))
    throw std::runtime_error("service " + name + " did not appear");
  return nh.serviceClient<Service>(name, /*persistent=*/true);
}

template <typename Service>
std::function<bool()> caller(ros::ServiceClient& client, Service& srv)
{
  return [&client, &srv] { return client.call(srv) && srv.response.success; };
}

/// Times `call` alternately with ~echo carrying `request_values` doubles up and `response_values`
/// down (the call's array payload), and appends both timings.
void timeAgainstEcho(const std::string& name, const std::function<bool()>& call, std::size_t request_values,
                     std::size_t response_values, ros::ServiceClient& echo_client, double budget,
                     std::vector<Timing>& timings)
{
  diff_rigid_body::Echo echo;
  echo.request.data.assign(request_values, 0.5);
  echo.request.response_size = static_cast<std::uint32_t>(response_values);
  auto [t, e] = timePair(name, call, "echo_for_" + name, caller(echo_client, echo), budget);
  t.request_bytes = e.request_bytes = 8 * request_values;
  t.response_bytes = e.response_bytes = 8 * response_values;
  timings.push_back(t);
  timings.push_back(e);
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

  std::vector<Timing> timings;
  // Everything with roscpp's default sockets first (what a roscpp client
  // gets), then ~ping and ~get_mass_matrix again with TCP_NODELAY.
  diff_rigid_body::Ping ping;
  diff_rigid_body::GetMassMatrix mass;
  mass.request.bodies = { bodies.response.names.front() };
  mass.request.q = { 0.3, -0.2, 0.1, 1.0, 2.0, 3.0 };
  {
    auto [m, p] = timePair("get_mass_matrix", caller(mass_client, mass), "ping", caller(ping_client, ping), budget);
    m.response_bytes = 36 * 8;
    timings.push_back(p);
    timings.push_back(m);
  }
  {
    // K = 1000 configurations of one body, against the same-size echo.
    diff_rigid_body::GetMassMatrix batch;
    batch.request.bodies = mass.request.bodies;
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    for (int i = 0; i < 6000; ++i)
      batch.request.q.push_back(u(rng));
    timeAgainstEcho("get_mass_matrix_K1000", caller(mass_client, batch), 6000, 37000, echo_client, budget, timings);
  }

  const std::vector<double> q = { 0.3, -1.2, 2.5, 0.5, -0.25, 1.5 };
  for (std::size_t b = 0; b < bodies.response.names.size(); ++b)
  {
    const std::string& body = bodies.response.names[b];
    const std::size_t n = bodies.response.vertex_counts[b];
    const std::string suffix = "/" + std::to_string(n);
    const double body_budget = n >= 100000 ? std::max(budget, 1.0) : budget;

    diff_rigid_body::GetVertexJacobians jac;
    jac.request.body = body;
    jac.request.q = q;
    diff_rigid_body::Echo echo;
    echo.request.response_size = static_cast<std::uint32_t>(21 * n);
    auto [t, e] = timePair("get_vertex_jacobians" + suffix, caller(jac_client, jac),
                           "echo_for_get_vertex_jacobians" + suffix, caller(echo_client, echo), body_budget);
    t.response_bytes = 21 * 8 * n;
    timings.push_back(t);
    e.response_bytes = t.response_bytes;
    timings.push_back(e);

    // Reduced transports, each with its same-size echo and its error
    // against the full answer (max |difference| / max |full value|, per field).
    struct Variant
    {
      const char* name;
      bool positions_only, single_precision;
      std::size_t bytes_per_vertex;
    };
    const Variant variants[] = { { "compact_rotation_block", false, false, 12 * 8 },
                                 { "compact_rotation_block_f32", false, true, 12 * 4 },
                                 { "compact_positions_only", true, false, 3 * 8 } };
    for (const Variant& v : variants)
    {
      diff_rigid_body::GetVertexJacobiansCompact compact;
      compact.request.body = body;
      compact.request.q = q;
      compact.request.positions_only = v.positions_only;
      compact.request.single_precision = v.single_precision;
      diff_rigid_body::Echo ce;
      ce.request.response_size = static_cast<std::uint32_t>((v.bytes_per_vertex * n + 7) / 8);
      auto [c, cet] = timePair(std::string(v.name) + suffix, caller(compact_client, compact),
                               std::string("echo_for_") + v.name + suffix, caller(echo_client, ce), body_budget);
      c.response_bytes = v.bytes_per_vertex * n;
      double pos_err = 0, pos_scale = 0, jac_err = 0, jac_scale = 0;
      for (std::size_t i = 0; i < 3 * n; ++i)
      {
        const double got = v.single_precision ? compact.response.positions_f32[i] : compact.response.positions[i];
        pos_err = std::max(pos_err, std::abs(got - jac.response.positions[i]));
        pos_scale = std::max(pos_scale, std::abs(jac.response.positions[i]));
      }
      if (!v.positions_only)
        for (std::size_t i = 0; i < n; ++i)
          for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k)
            {
              const double full = jac.response.jacobians[18 * i + 6 * r + k];
              const double got = v.single_precision ? compact.response.rotation_jacobians_f32[9 * i + 3 * r + k]
                                                    : compact.response.rotation_jacobians[9 * i + 3 * r + k];
              jac_err = std::max(jac_err, std::abs(got - full));
              jac_scale = std::max(jac_scale, std::abs(full));
            }
      char extra[160];
      std::snprintf(extra, sizeof(extra), "\"position_rel_error\": %.6g, \"jacobian_rel_error\": %.6g",
                    pos_scale > 0 ? pos_err / pos_scale : 0.0, jac_scale > 0 ? jac_err / jac_scale : 0.0);
      c.extra = extra;
      timings.push_back(c);
      cet.response_bytes = c.response_bytes;
      timings.push_back(cet);
    }

    diff_rigid_body::Backprop bp;
    bp.request.body = body;
    bp.request.q = q;
    bp.request.gradients.resize(3 * n);
    std::mt19937_64 rng(n);
    std::normal_distribution<double> g(0.0, 1.0);
    for (double& x : bp.request.gradients)
      x = g(rng);
    timeAgainstEcho("backprop" + suffix, caller(bp_client, bp), 3 * n, 6, echo_client, body_budget, timings);
    std::fprintf(stderr, "drb_bench_service: %s (%zu vertices) done\n", body.c_str(), n);
  }
  timeDynamics(nh, ns, bodies.response.names.front(), echo_client, budget, timings);

  // TCP_NODELAY on every connection of this client, then the small calls again.
  const int sockets = setNoDelayOnAllSockets();
  std::fprintf(stderr, "drb_bench_service: TCP_NODELAY on %d sockets\n", sockets);
  {
    auto [m, p] = timePair("get_mass_matrix_nodelay", caller(mass_client, mass), "ping_nodelay",
                           caller(ping_client, ping), budget);
    m.response_bytes = 36 * 8;
    timings.push_back(p);
    timings.push_back(m);
  }

  std::FILE* out = std::fopen(out_path.c_str(), "w");
  if (!out)
    throw std::runtime_error("cannot write " + out_path);
  std::fprintf(out, "{\"nodelay_sockets\": %d, \"timings\": [\n", sockets);
  for (std::size_t i = 0; i < timings.size(); ++i)
  {
    const Timing& t = timings[i];
    std::fprintf(out,
                 "  {\"name\": \"%s\", \"calls\": %zu, \"median_s\": %.6g, \"p25_s\": %.6g, \"p75_s\": %.6g, "
                 "\"min_s\": %.6g, \"request_bytes\": %zu, \"response_bytes\": %zu%s%s}%s\n",
                 t.name.c_str(), t.calls, t.median, t.p25, t.p75, t.min, t.request_bytes, t.response_bytes,
                 t.extra.empty() ? "" : ", ", t.extra.c_str(), i + 1 < timings.size() ? "," : "");
  }
  std::fprintf(out, "]}\n");
  std::fclose(out);
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
