// Time per operation of our kernels and of the peers, in one run:
//   mass_matrix/<method>              one M per iteration, angles vary per call
//   mass_matrix_batch/<method>/<K>    K matrices per iteration (K = 1: the
//                                     kernel of the node's single request)
//   mass_matrix_node/<bodies>/<K>     SceneQueries::massMatrices, the node's
//                                     whole call (checks, allocation, kernel)
//   jacobian/<vertex set>/<method>    all vertices of the set per iteration
//   backprop/<vertex set>/<method>    dL/dq over all vertices per iteration
// Each benchmark reports the counter "items" (operations per iteration), so
// time per operation = real_time / items. Run by scripts/bench with
// --benchmark_format=json; the errors come from drb_bench_accuracy.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <random>

#include "bench_common.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "methods.h"
#include "vertex_benchmarks.h"

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

  for (std::size_t K : { 1, 8, 64, 1024 })
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
/// A URDF of `bodies` free bodies "body<i>" on floating joints, each with
/// the benchmark body's mass [kg] and inertia about its COM [kg m^2] (link
/// frame at the COM), no geometry.
std::string freeBodiesUrdf(std::size_t bodies)
{
  const Matrix3d& I = body().inertia;
  char inertial[400];
  std::snprintf(inertial, sizeof(inertial),
                "<inertial><origin xyz=\"0 0 0\"/><mass value=\"%.17g\"/><inertia ixx=\"%.17g\" ixy=\"%.17g\" "
                "ixz=\"%.17g\" iyy=\"%.17g\" iyz=\"%.17g\" izz=\"%.17g\"/></inertial>",
                body().mass, I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2));
  std::string urdf = "<robot name=\"bench\"><link name=\"world\"/>";
  for (std::size_t i = 0; i < bodies; ++i)
  {
    const std::string name = "body" + std::to_string(i);
    urdf += "<link name=\"" + name + "\">" + inertial + "</link><joint name=\"" + name +
            "_joint\" type=\"floating\"><parent link=\"world\"/><child link=\"" + name + "\"/></joint>";
  }
  return urdf + "</robot>";
}

/// SceneQueries::massMatrices for K configurations of `bodies` bodies (the
/// benchmark body, and copies of it under other names): what the node runs
/// for ~get_mass_matrix, from the request's q to the answer's vectors.
void registerNodeMassMatrix(std::size_t bodies, std::size_t K)
{
  const std::string name = "mass_matrix_node/" + std::to_string(bodies) + "_bod" + (bodies == 1 ? "y/" : "ies/");
  benchmark::RegisterBenchmark((name + std::to_string(K)).c_str(), [=](benchmark::State& st) {
    const drb::Scene scene = drb::loadSceneFromUrdf(freeBodiesUrdf(bodies));
    std::vector<std::string> names;
    for (const drb::BodyModel& b : scene.bodies)
      names.push_back(b.name);
    const drb::SceneQueries queries(scene);
    const drb::SceneState current = queries.initialState();
    const std::vector<double>& packed = packedStates();
    const std::size_t per_call = 6 * K * bodies, windows = packed.size() / per_call;
    std::vector<std::vector<double>> q(windows);
    for (std::size_t w = 0; w < windows; ++w)
      q[w].assign(packed.begin() + static_cast<std::ptrdiff_t>(w * per_call),
                  packed.begin() + static_cast<std::ptrdiff_t>((w + 1) * per_call));
    std::size_t w = 0;
    for (auto _ : st)
    {
      drb::MassMatrixAnswer answer = queries.massMatrices(current, names, q[w], false);
      benchmark::DoNotOptimize(answer.mass_matrices.data());
      w = (w + 1) % windows;
    }
    st.counters["items"] = static_cast<double>(K * bodies);
    st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * K * bodies));
  });
}
}  // namespace

int main(int argc, char** argv)
{
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  registerMassMatrix();
  registerNodeMassMatrix(1, 1);
  registerNodeMassMatrix(1, 64);
  registerNodeMassMatrix(2, 64);
  registerJacobians();
  registerBackprop();
  for (const auto& ws : workspaces())
    benchmark::AddCustomContext("vertex_set." + ws->name, std::to_string(ws->count()));
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
