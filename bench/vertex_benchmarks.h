// The vertex-kernel benchmarks of drb_bench_kernels (bench_kernels.cpp):
//   jacobian/<vertex set>/<method>    all vertices of the set per iteration
//   backprop/<vertex set>/<method>    dL/dq over all vertices per iteration
// Rows named node_* run exactly the function SceneQueries (the node) calls
// for that request; floor_* rows only move the same bytes (memory_floors.h);
// every other row is a reference or a peer. bench/report.py names, per row,
// the function the node runs.
#pragma once

#include <benchmark/benchmark.h>

#include <cstring>
#include <functional>
#include <memory>
#include <numeric>
#include <random>

#include "bench_common.h"
#include "memory_floors.h"
#include "methods.h"

namespace drb_bench
{
inline const std::vector<Vector6d>& states()
{
  static const std::vector<Vector6d> s = timingStates(256);
  return s;
}

/// Runs `one(q)` per iteration with q cycling through the timing states.
template <typename F>
void perState(benchmark::State& st, std::size_t items, F&& one)
{
  const std::vector<Vector6d>& s = states();
  std::size_t i = 0;
  for (auto _ : st)
  {
    one(s[i]);
    i = (i + 1) & 255;
    benchmark::ClobberMemory();
  }
  st.counters["items"] = static_cast<double>(items);
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * items));
}

/// A vertex set with its outputs allocated and touched once (no page faults
/// and no allocation inside the timing loops). Outputs are std::vector, as
/// the node's answers are (same alignment, so the same store path).
struct Workspace
{
  std::string name;
  Matrix3Xd vertices;
  drb::VertexColumns<double> columns;  ///< the same vertices by coordinate (as the node keeps them)
  drb::Matrix3X<float> vertices_f;
  std::vector<std::uint32_t> all_indices;  ///< 0 .. N-1: a request that lists every vertex
  std::vector<double> jacobians, positions, gradients, memcpy_source;
  std::vector<float> jacobians_f, positions_f;

  Workspace(std::string n, Matrix3Xd v) : name(std::move(n)), vertices(std::move(v))
  {
    const std::size_t count = static_cast<std::size_t>(vertices.cols());
    columns = vertices.transpose();
    vertices_f = vertices.cast<float>();
    all_indices.resize(count);
    std::iota(all_indices.begin(), all_indices.end(), 0u);
    jacobians.assign(18 * count, 1.0);
    positions.assign(3 * count, 1.0);
    jacobians_f.assign(18 * count, 1.0f);
    positions_f.assign(3 * count, 1.0f);
    memcpy_source.assign(21 * count, 0.5);
    gradients.resize(3 * count);
    std::mt19937_64 rng(9);
    std::normal_distribution<double> g(0.0, 1.0);
    for (double& x : gradients)
      x = g(rng);
  }
  std::size_t count() const
  {
    return static_cast<std::size_t>(vertices.cols());
  }
};

inline std::vector<std::unique_ptr<Workspace>>& workspaces()
{
  static std::vector<std::unique_ptr<Workspace>> all = [] {
    std::vector<std::unique_ptr<Workspace>> w;
    for (VertexSet& set : jacobianVertexSets())
      w.push_back(std::make_unique<Workspace>(set.name, std::move(set.vertices)));
    return w;
  }();
  return all;
}

/// Registers `prefix + method`; sets of more than 10^5 vertices run longer.
inline benchmark::internal::Benchmark* addVertexBenchmark(const std::string& prefix, const std::string& method,
                                                           std::size_t n, std::function<void(benchmark::State&)> fn)
{
  auto* b = benchmark::RegisterBenchmark((prefix + method).c_str(), std::move(fn));
  if (n > 100000)
    b->MinTime(0.5);
  return b;
}

/// Floors at each SIMD width this CPU has (memory_floors.h).
inline std::vector<SimdPath> availablePaths()
{
  std::vector<SimdPath> paths;
  for (SimdPath p : { SimdPath::sse2, SimdPath::avx2, SimdPath::avx512 })
    if (cpuHas(p))
      paths.push_back(p);
  return paths;
}

inline void registerJacobianKernels(Workspace* ws, const std::string& prefix, std::size_t n)
{
  // SceneQueries::vertexJacobians: positions and J of all vertices.
  addVertexBenchmark(prefix, "node_positions_and_J", n, [ws, n](benchmark::State& st) {
    perState(st, n, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      drb::vertexPositionsAndJacobians<double>(pose, ws->vertices, {}, ws->positions.data(), ws->jacobians.data());
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
  // SceneQueries::vertexRotationJacobians<double / float>: the compact service.
  addVertexBenchmark(prefix, "node_compact_rotation_block", n, [ws, n](benchmark::State& st) {
    perState(st, n, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      drb::vertexPositionsAndRotationJacobians<double, double>(pose, ws->vertices, {}, ws->positions.data(),
                                                               ws->jacobians.data());
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
  addVertexBenchmark(prefix, "node_compact_rotation_block_float32", n, [ws, n](benchmark::State& st) {
    perState(st, n, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      drb::vertexPositionsAndRotationJacobians<double, float>(pose, ws->vertices, {}, ws->positions_f.data(),
                                                              ws->jacobians_f.data());
      benchmark::DoNotOptimize(ws->jacobians_f.data());
    });
  });
  // References: J alone (no positions), and the float kernel.
  addVertexBenchmark(prefix, "ours_double", n, [ws, n](benchmark::State& st) {
    perState(st, n, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      drb::vertexPositionsAndJacobians<double>(pose, ws->vertices, {}, nullptr, ws->jacobians.data());
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
  addVertexBenchmark(prefix, "ours_float", n, [ws, n](benchmark::State& st) {
    perState(st, n, [&](const Vector6d& q) {
      const drb::BodyPose<float> pose(q.cast<float>());
      drb::vertexPositionsAndJacobians<float>(pose, ws->vertices_f, {}, nullptr, ws->jacobians_f.data());
      benchmark::DoNotOptimize(ws->jacobians_f.data());
    });
  });
}

inline void registerJacobianFloorsAndPeers(Workspace* ws, const std::string& prefix, std::size_t n)
{
  for (SimdPath path : availablePaths())
    addVertexBenchmark(prefix, std::string("floor_write_168B_") + pathName(path), n, [ws, n, path](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        writeFloor(path, ws->positions.data(), ws->jacobians.data(), n, q[0]);
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
  addVertexBenchmark(prefix, "memcpy_168B", n, [ws, n](benchmark::State& st) {
    perState(st, n, [&](const Vector6d&) {
      std::memcpy(ws->jacobians.data(), ws->memcpy_source.data(), 144 * n);
      std::memcpy(ws->positions.data(), ws->memcpy_source.data() + 18 * n, 24 * n);
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
  addVertexBenchmark(prefix, "central_diff", n, [ws, n](benchmark::State& st) {
    const CentralDifferences fd;
    perState(st, n, [&](const Vector6d& q) {
      fd(q, ws->vertices, ws->jacobians.data());
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
  addVertexBenchmark(prefix, "complex_step", n, [ws, n](benchmark::State& st) {
    const ComplexStep cs;
    perState(st, n, [&](const Vector6d& q) {
      cs(q, ws->vertices, ws->jacobians.data());
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
#ifdef DRB_BENCH_HAVE_KDL
  addVertexBenchmark(prefix, "kdl", n, [ws, n](benchmark::State& st) {
    KdlJacobians kdl;
    perState(st, n, [&](const Vector6d& q) {
      kdl(q, ws->vertices, ws->jacobians.data());
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  addVertexBenchmark(prefix, "mujoco", n, [ws, n](benchmark::State& st) {
    MujocoBody mj(1.0, Matrix3d::Identity());
    perState(st, n, [&](const Vector6d& q) {
      mj.jacobians(q, ws->vertices, ws->jacobians.data());
      benchmark::DoNotOptimize(ws->jacobians.data());
    });
  });
#endif
}

inline void registerJacobians()
{
  for (const auto& w : workspaces())
  {
    const std::string prefix = "jacobian/" + w->name + "/";
    registerJacobianKernels(w.get(), prefix, w->count());
    registerJacobianFloorsAndPeers(w.get(), prefix, w->count());
  }
}

/// Backprop rows that evaluate `fn(pose)` per state.
template <typename F>
void addBackprop(const std::string& prefix, const std::string& method, std::size_t n, F fn)
{
  addVertexBenchmark(prefix, method, n, [n, fn](benchmark::State& st) {
    perState(st, n, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      Vector6d g = fn(pose);
      benchmark::DoNotOptimize(g.data());
    });
  });
}

inline void registerBackpropSet(Workspace* ws)
{
  const std::string prefix = "backprop/" + ws->name + "/";
  const std::size_t n = ws->count();
  const double* g = ws->gradients.data();
  // SceneQueries::backprop, all vertices: by coordinate, dispatched from CPUID.
  addBackprop(prefix, "node_columns", n, [ws, g](const drb::BodyPose<double>& pose) {
    return drb::backpropagateVertexGradients(pose, ws->columns, g);
  });
  // The same sum forced onto each SIMD path (AVX2: the node on an AVX2-only CPU).
  for (SimdPath path : availablePaths())
    addBackprop(prefix, std::string("columns_on_") + pathName(path), n,
                [ws, g, path](const drb::BodyPose<double>& pose) {
                  return backpropColumnsOnPath(path, pose, ws->columns, g);
                });
  // SceneQueries::backprop with an index list (here every vertex, listed).
  addBackprop(prefix, "node_index_list", n, [ws, g](const drb::BodyPose<double>& pose) {
    return drb::backpropagateVertexGradients(pose, ws->columns, ws->all_indices, g);
  });
  // References: the 3xN kernel (vertex_jacobian.h); two threads (wall time).
  addBackprop(prefix, "ours_double", n, [ws, g](const drb::BodyPose<double>& pose) {
    return drb::backpropagateVertexGradients(pose, ws->vertices, {}, g);
  });
  addVertexBenchmark(prefix, "ours_columns_2_threads", n, [ws, n, g](benchmark::State& st) {
    perState(st, n, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      Vector6d out = drb::backpropagateVertexGradients(pose, ws->columns, g, 2);
      benchmark::DoNotOptimize(out.data());
    });
  })->UseRealTime();
  addBackprop(prefix, "form_J_and_multiply", n, [ws, g](const drb::BodyPose<double>& pose) {
    return backpropFormJ(pose, ws->vertices, g);
  });
  addBackprop(prefix, "J_buffer_then_multiply", n, [ws, g](const drb::BodyPose<double>& pose) {
    return backpropViaBuffer(pose, ws->vertices, g, ws->jacobians.data());
  });
  for (SimdPath path : availablePaths())
    addVertexBenchmark(prefix, std::string("floor_read_48B_") + pathName(path), n, [ws, n, g, path](benchmark::State& st) {
      perState(st, n, [&](const Vector6d&) {
        double sum = readFloor(path, ws->columns, g);
        benchmark::DoNotOptimize(sum);
      });
    });
}

inline void registerBackprop()
{
  // The per-call part every method pays: q -> R, T (three sin/cos pairs).
  benchmark::RegisterBenchmark("backprop_fixed/body_pose", [](benchmark::State& st) {
    perState(st, 1, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      benchmark::DoNotOptimize(&pose);
    });
  });
  // The node's path with no vertex: the pose, the SIMD set-up and lane
  // reductions, and dL/dq from the sums; what a call costs beyond its vertices.
  benchmark::RegisterBenchmark("backprop_fixed/node_columns_no_vertices", [](benchmark::State& st) {
    const drb::VertexColumns<double> none(0, 3);
    perState(st, 1, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      Vector6d g = drb::backpropagateVertexGradients(pose, none, nullptr);
      benchmark::DoNotOptimize(g.data());
    });
  });
  for (const auto& w : workspaces())
    registerBackpropSet(w.get());
}

}  // namespace drb_bench
