// Timing of roscpp service calls for bench/bench_service.cpp: calls timed
// alternately with a reference call (~ping or ~echo of the same payload), so
// that both see the same machine load, and the timings written as JSON.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <ros/ros.h>

#include <diff_rigid_body/Echo.h>

namespace drb_bench
{
using Clock = std::chrono::steady_clock;

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
inline std::pair<Timing, Timing> timePair(const std::string& name_a, const std::function<bool()>& a,
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
inline void timeAgainstEcho(const std::string& name, const std::function<bool()>& call,
                            std::size_t request_values, std::size_t response_values,
                            ros::ServiceClient& echo_client, double budget, std::vector<Timing>& timings)
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

/// Writes {"nodelay_sockets": N, "timings": [...]}, one object per timing (seconds per call).
inline void writeTimings(const std::string& out_path, int nodelay_sockets, const std::vector<Timing>& timings)
{
  std::FILE* out = std::fopen(out_path.c_str(), "w");
  if (!out)
    throw std::runtime_error("cannot write " + out_path);
  std::fprintf(out, "{\"nodelay_sockets\": %d, \"timings\": [\n", nodelay_sockets);
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
}
}  // namespace drb_bench
