// drb_bench_local: the C++ side of docs/benchmarks.md's "In process" rows. Each
// row runs the SceneQueries member that diff_rigid_body.LocalScene calls
// (src/python/local_scene_queries.cpp), as LocalScene runs it (a fresh answer
// per call), on the inputs bench/local_throughput.py gives LocalScene:
//   local/<robot>/mass_matrix_K1      massMatrices, all bodies, K = 1
//   local/ur5/backprop_K1000_N400     backpropConfigurations, K = 1000
//                                     configurations, 400 vertices (9.6 MB of
//                                     gradients)
// Inputs, exact binary fractions so that numpy builds the same bits:
//   q[k, j] = ((7 k + 13 j) mod 41 - 20) / 32            [rad, m]
//   (the Panda's finger, coordinate 7: 1/64 m, inside its limits)
//   dL/dp[k, v, c] = ((5 k + 11 v + 3 c) mod 29 - 14) / 16
//   vertex i of 400: floor(i N / 400), N the body's vertex count.
// The gradients lie in memory as numpy holds them (transparent huge pages for >= 4 MiB).
// Items: 1 per call ("items" counter), so time per call = real_time.
#include <benchmark/benchmark.h>

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "diff_rigid_body/parsers/urdf_scene.h"
#include "diff_rigid_body/services/scene_queries.h"

namespace
{
namespace drb = diff_rigid_body;

std::string robotDir()
{
#ifdef DRB_ROBOT_DIR
  return DRB_ROBOT_DIR;
#else
  return "(DRB_ROBOT_DIR not defined by the build)";
#endif
}

/// The scene as LocalScene loads it with its defaults (collision geometry, joints modelled).
std::shared_ptr<const drb::SceneQueries> load(const std::string& urdf)
{
  const std::string root = robotDir();
  drb::SceneOptions options;
  options.find_package = [root](const std::string& package) {
    return package == "drb_example_robot_data" ? root : std::string();
  };
  return std::make_shared<const drb::SceneQueries>(
      drb::loadSceneFromUrdfFile(root + "/robots/" + urdf, options));
}

/// K configurations of d coordinates, row-major (the formula above).
std::vector<double> configurations(std::size_t K, std::size_t d, bool panda)
{
  std::vector<double> q(K * d);
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t j = 0; j < d; ++j)
      q[k * d + j] = (panda && j == 7) ? 1.0 / 64 : (double((7 * k + 13 * j) % 41) - 20.0) / 32.0;
  return q;
}

/// n doubles where numpy keeps a large array: an array of >= 4 MiB is advised to transparent huge
/// pages (numpy's alloc.c: madvise(MADV_HUGEPAGE)), which LocalScene's core then reads in place.
std::shared_ptr<double> numpyLikeBuffer(std::size_t n)
{
  const std::size_t huge = std::size_t(1) << 21, bytes = (n * sizeof(double) + huge - 1) / huge * huge;
  auto* data = static_cast<double*>(std::aligned_alloc(huge, bytes));
  if (data == nullptr)
    throw std::bad_alloc();
  if (n * sizeof(double) >= (std::size_t(1) << 22))
    madvise(data, bytes, MADV_HUGEPAGE);
  return std::shared_ptr<double>(data, [](double* p) { std::free(p); });
}

void mark(benchmark::State& st)
{
  st.counters["items"] = 1.0;
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations()));
}

void registerMassMatrix(const std::string& robot, const std::string& urdf)
{
  auto queries = load(urdf);
  std::size_t d = 0;
  for (const drb::BodyModel& body : queries->scene().bodies)
    d += body.coordinates;
  auto q = std::make_shared<std::vector<double>>(configurations(1, d, robot == "panda"));
  benchmark::RegisterBenchmark(("local/" + robot + "/mass_matrix_K1").c_str(), [queries, q](benchmark::State& st) {
    const drb::SceneState current = queries->initialState();
    for (auto _ : st)
    {
      drb::MassMatrixAnswer answer;  // _local Scene.get_mass_matrix: a fresh answer per call
      queries->massMatrices(current, {}, *q, false, answer);
      benchmark::DoNotOptimize(answer.mass_matrices.data());
    }
    mark(st);
  });
}

void registerBackprop(std::size_t K, std::size_t N)
{
  auto queries = load("ur_description/urdf/ur5_robot.urdf");
  const drb::BodyModel& body = queries->scene().bodies.at(0);
  auto vertices = std::make_shared<std::vector<std::uint32_t>>(N);
  for (std::size_t i = 0; i < N; ++i)
    (*vertices)[i] = static_cast<std::uint32_t>(i * body.vertexCount() / N);
  auto q = std::make_shared<std::vector<double>>(configurations(K, body.coordinates, false));
  const std::size_t size = K * N * 3;
  std::shared_ptr<double> gradients = numpyLikeBuffer(size);
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t v = 0; v < N; ++v)
      for (std::size_t c = 0; c < 3; ++c)
        gradients.get()[(k * N + v) * 3 + c] = (double((5 * k + 11 * v + 3 * c) % 29) - 14.0) / 16.0;
  const std::string name = "local/ur5/backprop_K" + std::to_string(K) + "_N" + std::to_string(N);
  const std::string body_name = body.name;
  benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) {
    const drb::SceneState current = queries->initialState();
    for (auto _ : st)
    {
      std::vector<double> gradient;  // _local Scene.backprop: a fresh answer per call
      queries->backpropConfigurations(current, body_name, *vertices, drb::DoubleView(gradients.get(), size), *q,
                                      gradient);
      benchmark::DoNotOptimize(gradient.data());
    }
    mark(st);
  });
  benchmark::AddCustomContext("local.ur5.vertices", std::to_string(body.vertexCount()));
  benchmark::AddCustomContext("local.ur5.body", body_name);
}
}  // namespace

int main(int argc, char** argv)
{
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  registerMassMatrix("ur5", "ur_description/urdf/ur5_robot.urdf");
  registerMassMatrix("panda", "panda_description/urdf/panda.urdf");
  registerBackprop(1000, 400);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
