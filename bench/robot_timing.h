// The timing loop of drb_bench_articulated's rows: one call per iteration,
// the robot's 256 states in turn (no two consecutive calls see the same
// configuration). Each benchmark reports the counter "items" (matrices,
// configurations or vertices per iteration): time per item = time / items.
#pragma once

#include <benchmark/benchmark.h>

#include <functional>
#include <string>

#include "body_robots.h"

namespace drb_bench
{
/// Runs `one(i)` per iteration for state i = 0, 1, ..., 255, 0, ...
template <typename F>
void perState(benchmark::State& st, const Robot& robot, std::size_t items, F&& one)
{
  std::size_t i = 0;
  for (auto _ : st)
  {
    one(i);
    i = (i + 1) % robot.states.size();
    benchmark::ClobberMemory();
  }
  st.counters["items"] = static_cast<double>(items);
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * items));
}

inline void addBenchmark(const std::string& name, std::function<void(benchmark::State&)> fn)
{
  benchmark::RegisterBenchmark(name.c_str(), std::move(fn));
}

/// The rows of bench_bodies.cpp (kinematics, M, dM/dx, vertices) and
/// bench_dynamics.cpp (inverse and forward dynamics, their derivatives).
void registerBodyRows(const Robot& robot);
void registerVertexRows(const Robot& robot);
void registerDynamicsRows(const Robot& robot);
/// frame_jacobian and com_jacobian rows (bench_frames.cpp).
void registerFrameRows(const Robot& robot);

}  // namespace drb_bench
