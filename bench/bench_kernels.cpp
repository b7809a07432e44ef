// Time per operation of our kernels and of the peers, in one run:
//   mass_matrix/<method>              one M per iteration, angles vary per call
//   mass_matrix_batch/<method>/<K>    K matrices per iteration
//   jacobian/<vertex set>/<method>    all vertices of the set per iteration
//   backprop/<vertex set>/<method>    dL/dq over all vertices per iteration
// Each benchmark reports the counter "items" (operations per iteration), so
// time per operation = real_time / items. Run by scripts/bench with
// --benchmark_format=json; the errors come from drb_bench_accuracy.
#include <benchmark/benchmark.h>

#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <random>

#include "bench_common.h"
#include "methods.h"

namespace
{
using namespace drb_bench;

struct Body
{
  double mass = 2.5;
  Matrix3d inertia;
  Body()
  {
    std::mt19937_64 rng(5);
    inertia = randomInertia(rng, 0.4);
  }
};

const Body& body()
{
  static const Body b;
  return b;
}

const std::vector<Vector6d>& states()
{
  static const std::vector<Vector6d> s = timingStates(256);
  return s;
}

/// 4096 states back to back (6 doubles each) for the batched kernels.
const std::vector<double>& packedStates()
{
  static const std::vector<double> packed = [] {
    const std::vector<Vector6d> s = timingStates(4096);
    std::vector<double> out;
    for (const Vector6d& q : s)
      out.insert(out.end(), q.data(), q.data() + 6);
    return out;
  }();
  return packed;
}

/// A vertex set with its outputs allocated and touched once (no page faults
/// and no allocation inside the timing loops).
struct Workspace
{
  std::string name;
  Matrix3Xd vertices;
  drb::VertexColumns<double> columns;  ///< the same vertices by coordinate (as the node keeps them)
  drb::Matrix3X<float> vertices_f;
  std::vector<double> jacobians, positions, gradients, memcpy_source;
  std::vector<float> jacobians_f;

  Workspace(std::string n, Matrix3Xd v) : name(std::move(n)), vertices(std::move(v))
  {
    const std::size_t count = static_cast<std::size_t>(vertices.cols());
    columns = vertices.transpose();
    vertices_f = vertices.cast<float>();
    jacobians.assign(18 * count, 1.0);
    positions.assign(3 * count, 1.0);
    jacobians_f.assign(18 * count, 1.0f);
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

std::vector<std::unique_ptr<Workspace>>& workspaces()
{
  static std::vector<std::unique_ptr<Workspace>> all = [] {
    std::vector<std::unique_ptr<Workspace>> w;
    for (VertexSet& set : jacobianVertexSets())
      w.push_back(std::make_unique<Workspace>(set.name, std::move(set.vertices)));
    return w;
  }();
  return all;
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

void registerMassMatrix()
{
  const double mass = body().mass;
  const Matrix3d I = body().inertia;
  benchmark::RegisterBenchmark("mass_matrix/ours_double", [=](benchmark::State& st) {
    Matrix6d M;
    perState(st, 1, [&](const Vector6d& q) {
      M = drb::massMatrix(q, mass, I);
      benchmark::DoNotOptimize(M.data());
    });
  });
  benchmark::RegisterBenchmark("mass_matrix/ours_float", [=](benchmark::State& st) {
    const Eigen::Matrix3f If = I.cast<float>();
    const float mf = static_cast<float>(mass);
    drb::Matrix6<float> M;
    perState(st, 1, [&](const Vector6d& q) {
      const drb::Vector6<float> qf = q.cast<float>();
      M = drb::massMatrix(qf, mf, If);
      benchmark::DoNotOptimize(M.data());
    });
  });
  benchmark::RegisterBenchmark("mass_matrix/fd_energy", [=](benchmark::State& st) {
    const EnergyFiniteDifferences fd{ mass, I };
    double out[36];
    perState(st, 1, [&](const Vector6d& q) {
      fd(q, out);
      benchmark::DoNotOptimize(out);
    });
  });
#ifdef DRB_BENCH_HAVE_KDL
  benchmark::RegisterBenchmark("mass_matrix/kdl", [=](benchmark::State& st) {
    KdlMassMatrix kdl(mass, I);
    double out[36];
    perState(st, 1, [&](const Vector6d& q) {
      kdl(q, out);
      benchmark::DoNotOptimize(out);
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  benchmark::RegisterBenchmark("mass_matrix/mujoco", [=](benchmark::State& st) {
    MujocoBody mj(mass, I);
    double out[36];
    perState(st, 1, [&](const Vector6d& q) {
      mj.massMatrix(q, out);
      benchmark::DoNotOptimize(out);
    });
  });
  benchmark::RegisterBenchmark("mass_matrix/mujoco_fwdPosition", [=](benchmark::State& st) {
    MujocoBody mj(mass, I);
    double out[36];
    perState(st, 1, [&](const Vector6d& q) {
      mj.massMatrixFwdPosition(q, out);
      benchmark::DoNotOptimize(out);
    });
  });
#endif

  for (std::size_t K : { 8, 64, 1024 })
  {
    benchmark::RegisterBenchmark(("mass_matrix_batch/ours_double/" + std::to_string(K)).c_str(),
                                 [=](benchmark::State& st) {
                                   const std::vector<double>& q = packedStates();
                                   std::vector<double> out(36 * K), cos_theta(K);
                                   const std::size_t windows = 4096 / K;
                                   std::size_t w = 0;
                                   for (auto _ : st)
                                   {
                                     drb::massMatrixBatch(q.data() + 6 * K * w, K, 6, mass, I, out.data(),
                                                          cos_theta.data());
                                     benchmark::DoNotOptimize(out.data());
                                     benchmark::ClobberMemory();
                                     w = (w + 1) % windows;
                                   }
                                   st.counters["items"] = static_cast<double>(K);
                                   st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * K));
                                 });
#ifdef DRB_BENCH_HAVE_MUJOCO
    // MuJoCo has no batched M: K calls of the minimal pipeline.
    if (K == 64)
      benchmark::RegisterBenchmark(("mass_matrix_batch/mujoco/" + std::to_string(K)).c_str(),
                                   [=](benchmark::State& st) {
                                     MujocoBody mj(mass, I);
                                     const std::vector<double>& q = packedStates();
                                     std::vector<double> out(36 * K);
                                     const std::size_t windows = 4096 / K;
                                     std::size_t w = 0;
                                     for (auto _ : st)
                                     {
                                       for (std::size_t k = 0; k < K; ++k)
                                         mj.massMatrix(Eigen::Map<const Vector6d>(q.data() + 6 * (K * w + k)),
                                                       out.data() + 36 * k);
                                       benchmark::DoNotOptimize(out.data());
                                       w = (w + 1) % windows;
                                     }
                                     st.counters["items"] = static_cast<double>(K);
                                     st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * K));
                                   });
#endif
  }
}

void registerJacobians()
{
  for (std::size_t index = 0; index < workspaces().size(); ++index)
  {
    Workspace* ws = workspaces()[index].get();
    const std::string prefix = "jacobian/" + ws->name + "/";
    const std::size_t n = ws->count();
    const bool huge = n > 100000;
    auto add = [&](const std::string& method, std::function<void(benchmark::State&)> fn) {
      auto* b = benchmark::RegisterBenchmark((prefix + method).c_str(), fn);
      if (huge)
        b->MinTime(0.5);
    };
    add("ours_double", [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        drb::vertexPositionsAndJacobians<double>(pose, ws->vertices, {}, nullptr, ws->jacobians.data());
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
    add("ours_double_with_positions", [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        drb::vertexPositionsAndJacobians<double>(pose, ws->vertices, {}, ws->positions.data(), ws->jacobians.data());
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
    add("ours_float", [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<float> pose(q.cast<float>());
        drb::vertexPositionsAndJacobians<float>(pose, ws->vertices_f, {}, nullptr, ws->jacobians_f.data());
        benchmark::DoNotOptimize(ws->jacobians_f.data());
      });
    });
    add("ours_rotation_block_double", [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        drb::vertexPositionsAndRotationJacobians<double, double>(pose, ws->vertices, {}, nullptr,
                                                                 ws->jacobians.data());
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
    add("memcpy_144B", [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d&) {
        std::memcpy(ws->jacobians.data(), ws->memcpy_source.data(), 144 * n);
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
    add("memcpy_168B", [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d&) {
        std::memcpy(ws->jacobians.data(), ws->memcpy_source.data(), 144 * n);
        std::memcpy(ws->positions.data(), ws->memcpy_source.data() + 18 * n, 24 * n);
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
    add("memcpy_72B", [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d&) {
        std::memcpy(ws->jacobians_f.data(), ws->memcpy_source.data(), 72 * n);
        benchmark::DoNotOptimize(ws->jacobians_f.data());
      });
    });
    add("central_diff", [ws, n](benchmark::State& st) {
      const CentralDifferences fd;
      perState(st, n, [&](const Vector6d& q) {
        fd(q, ws->vertices, ws->jacobians.data());
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
    add("complex_step", [ws, n](benchmark::State& st) {
      const ComplexStep cs;
      perState(st, n, [&](const Vector6d& q) {
        cs(q, ws->vertices, ws->jacobians.data());
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
#ifdef DRB_BENCH_HAVE_KDL
    add("kdl", [ws, n](benchmark::State& st) {
      KdlJacobians kdl;
      perState(st, n, [&](const Vector6d& q) {
        kdl(q, ws->vertices, ws->jacobians.data());
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
    add("mujoco", [ws, n](benchmark::State& st) {
      MujocoBody mj(1.0, Matrix3d::Identity());
      perState(st, n, [&](const Vector6d& q) {
        mj.jacobians(q, ws->vertices, ws->jacobians.data());
        benchmark::DoNotOptimize(ws->jacobians.data());
      });
    });
#endif
  }
}

void registerBackprop()
{
  // The per-call part every method pays: q -> R, T (three sin/cos pairs).
  benchmark::RegisterBenchmark("backprop_fixed/body_pose", [](benchmark::State& st) {
    perState(st, 1, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      benchmark::DoNotOptimize(&pose);
    });
  });
  // Ours with no vertex: the pose, the SIMD set-up and lane reductions, and
  // dL/dq from the sums; what a call costs beyond its vertices.
  benchmark::RegisterBenchmark("backprop_fixed/ours_columns_no_vertices", [](benchmark::State& st) {
    const drb::VertexColumns<double> none(0, 3);
    perState(st, 1, [&](const Vector6d& q) {
      const drb::BodyPose<double> pose(q);
      Vector6d g = drb::backpropagateVertexGradients(pose, none, nullptr);
      benchmark::DoNotOptimize(g.data());
    });
  });
  for (std::size_t index = 0; index < workspaces().size(); ++index)
  {
    Workspace* ws = workspaces()[index].get();
    const std::string prefix = "backprop/" + ws->name + "/";
    const std::size_t n = ws->count();
    benchmark::RegisterBenchmark((prefix + "ours_double").c_str(), [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        Vector6d g = drb::backpropagateVertexGradients(pose, ws->vertices, {}, ws->gradients.data());
        benchmark::DoNotOptimize(g.data());
      });
    });
    benchmark::RegisterBenchmark((prefix + "ours_columns").c_str(), [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        Vector6d g = drb::backpropagateVertexGradients(pose, ws->columns, ws->gradients.data());
        benchmark::DoNotOptimize(g.data());
      });
    });
    // Wall time: CPU time would count the calling thread only.
    benchmark::RegisterBenchmark((prefix + "ours_columns_2_threads").c_str(), [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        Vector6d g = drb::backpropagateVertexGradients(pose, ws->columns, ws->gradients.data(), 2);
        benchmark::DoNotOptimize(g.data());
      });
    })->UseRealTime();
    benchmark::RegisterBenchmark((prefix + "form_J_and_multiply").c_str(), [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        Vector6d g = backpropFormJ(pose, ws->vertices, ws->gradients.data());
        benchmark::DoNotOptimize(g.data());
      });
    });
    benchmark::RegisterBenchmark((prefix + "J_buffer_then_multiply").c_str(), [ws, n](benchmark::State& st) {
      perState(st, n, [&](const Vector6d& q) {
        const drb::BodyPose<double> pose(q);
        Vector6d g = backpropViaBuffer(pose, ws->vertices, ws->gradients.data(), ws->jacobians.data());
        benchmark::DoNotOptimize(g.data());
      });
    });
  }
}
}  // namespace

int main(int argc, char** argv)
{
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  registerMassMatrix();
  registerJacobians();
  registerBackprop();
  for (const auto& ws : workspaces())
    benchmark::AddCustomContext("vertex_set." + ws->name, std::to_string(ws->count()));
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
