// Joint-space (articulated) bodies: the Panda and the UR5 of test/robots in
// model mode, against KDL and MuJoCo on the same URDFs, in one run:
//   articulated_mass_matrix/<robot>/<method>   one M(x) per iteration, x cycling
//                                              through 256 configurations
//   articulated_pose/<robot>/ours              articulatedPose alone
//   articulated_jacobian/panda/<method>        positions + J of every vertex
//   articulated_backprop/panda/<method>        dL/dx over every vertex
// Methods: ours (articulatedPose, then the kernel: what SceneQueries runs per
// configuration), ours_derivatives (dM/dx), node_call (the SceneQueries call:
// checks, answer vectors, kernel), ours_kernel (the pose made outside the
// loop), kdl, mujoco, mujoco_fwdPosition, and floors
// (loops that only move the kernel's bytes, memory_floors.h). Each benchmark
// reports the counter "items" (matrices or vertices per iteration): time per
// item = time / items. Errors (articulated_errors.h) and the models' sizes
// and masses go into the JSON's context as "articulated.<robot>.<key>". Run
// by scripts/bench; bench/report_articulated.py writes the docs section.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <numeric>
#include <random>

#include "articulated_errors.h"
#include "articulated_peers.h"
#include "diff_rigid_body/articulated_queries.h"
#include "memory_floors.h"

namespace
{
using namespace drb_bench;

/// Runs `one(x)` per iteration with x cycling through the robot's states.
template <typename F>
void perConfiguration(benchmark::State& st, const Robot& robot, std::size_t items, F&& one)
{
  std::size_t i = 0;
  for (auto _ : st)
  {
    one(robot.states[i].data());
    i = (i + 1) % robot.states.size();
    benchmark::ClobberMemory();
  }
  st.counters["items"] = static_cast<double>(items);
  st.SetItemsProcessed(static_cast<std::int64_t>(st.iterations() * items));
}

void add(const std::string& name, std::function<void(benchmark::State&)> fn)
{
  benchmark::RegisterBenchmark(name.c_str(), std::move(fn));
}

void registerMassMatrix(const Robot& robot)
{
  const std::string prefix = "articulated_mass_matrix/" + robot.name + "/";
  const drb::ArticulatedBody* body = robot.body.get();
  // What SceneQueries::massMatrices runs per configuration of an articulated body.
  add(prefix + "ours", [&robot, body](benchmark::State& st) {
    perConfiguration(st, robot, 1, [&](const double* x) {
      const Eigen::MatrixXd M = drb::articulatedMassMatrix(*body, drb::articulatedPose(*body, x));
      benchmark::DoNotOptimize(M.data());
    });
  });
  add("articulated_pose/" + robot.name + "/ours", [&robot, body](benchmark::State& st) {
    perConfiguration(st, robot, 1, [&](const double* x) {
      const drb::ArticulatedPose<double> pose = drb::articulatedPose(*body, x);
      benchmark::DoNotOptimize(pose.frames.data());
    });
  });
  // The node's whole call for one configuration (checks, answer vectors, kernel).
  add(prefix + "node_call", [&robot](benchmark::State& st) {
    const drb::SceneState current = robot.queries->initialState();
    const std::vector<std::string> names = { robot.body_name };
    perConfiguration(st, robot, 1, [&](const double* x) {
      const std::vector<double> q(x, x + robot.body->dofs());
      drb::MassMatrixAnswer answer = robot.queries->massMatrices(current, names, q, false);
      benchmark::DoNotOptimize(answer.mass_matrices.data());
    });
  });
  add(prefix + "ours_derivatives", [&robot, body](benchmark::State& st) {
    perConfiguration(st, robot, 1, [&](const double* x) {
      const std::vector<Eigen::MatrixXd> dM = drb::articulatedMassMatrixDerivatives(*body, x);
      benchmark::DoNotOptimize(dM.data());
    });
  });
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  const std::vector<std::string> chain_links = KdlArm(robot).links;
  // Ours on the mass KDL's chain covers, where that is less than the body's
  // (the Panda: its right finger is off the chain).
  bool off_chain_mass = false;
  for (const drb::Segment& s : body->segments)
    off_chain_mass |= s.mass_properties.mass > 0 &&
                      std::find(chain_links.begin(), chain_links.end(), s.link) == chain_links.end();
  if (off_chain_mass)
    add(prefix + "ours_chain_mass", [&robot, chain_links](benchmark::State& st) {
      const drb::ArticulatedBody on_chain = massOnlyIn(*robot.body, chain_links);
      perConfiguration(st, robot, 1, [&](const double* x) {
        const Eigen::MatrixXd M = drb::articulatedMassMatrix(on_chain, drb::articulatedPose(on_chain, x));
        benchmark::DoNotOptimize(M.data());
      });
    });
  add(prefix + "kdl", [&robot](benchmark::State& st) {
    KdlArm kdl(robot);
    perConfiguration(st, robot, 1, [&](const double* x) {
      kdl.massMatrix(x);
      benchmark::DoNotOptimize(kdl.H.data.data());
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  add(prefix + "mujoco", [&robot](benchmark::State& st) {
    MujocoArm mj(robot);
    perConfiguration(st, robot, 1, [&](const double* x) {
      mj.massMatrix(x);
      benchmark::DoNotOptimize(mj.dense.data());
    });
  });
  add(prefix + "mujoco_fwdPosition", [&robot](benchmark::State& st) {
    MujocoArm mj(robot);
    perConfiguration(st, robot, 1, [&](const double* x) {
      mj.massMatrixFwdPosition(x);
      benchmark::DoNotOptimize(mj.dense.data());
    });
  });
#endif
}

/// The best SIMD path of this CPU for the floors.
SimdPath bestPath()
{
  for (SimdPath p : { SimdPath::avx512, SimdPath::avx2 })
    if (cpuHas(p))
      return p;
  return SimdPath::sse2;
}

/// Reads the 3N gradients and the 3N vertex coordinates once (48 B per vertex).
double readOnce(SimdPath path, const drb::Matrix3X<double>& vertices, const double* g)
{
  const std::size_t n = static_cast<std::size_t>(vertices.cols());
  const double* v = vertices.data();  // x, y, z "columns" = the 3N values, each read once
#if defined(DRB_BENCH_SIMD_PATHS)
  if (path == SimdPath::avx512)
    return floors::read8(v, v + n, v + 2 * n, g, n);
  if (path == SimdPath::avx2)
    return floors::read4(v, v + n, v + 2 * n, g, n);
  return floors::read2(v, v + n, v + 2 * n, g, n);
#else
  (void)path;
  double sum = 0;
  for (std::size_t i = 0; i < 3 * n; ++i)
    sum += v[i] + g[i];
  return sum;
#endif
}

/// Writes `count` doubles once with ordinary stores (the kernel does not stream).
void writeOnce(SimdPath path, double* out, std::size_t count)
{
#if defined(DRB_BENCH_SIMD_PATHS)
  if (path == SimdPath::avx512)
    floors::write8(out, count, 1.0, false);
  else if (path == SimdPath::avx2)
    floors::write4(out, count, 1.0, false);
  else
    floors::write2(out, count, 1.0, false);
#else
  (void)path;
  std::fill(out, out + count, 1.0);
#endif
}

/// Outputs and gradients of every vertex of a robot, allocated and touched once.
struct VertexWork
{
  std::size_t count, dofs;
  std::vector<double> positions, jacobians, gradients, dLdx;
  explicit VertexWork(const drb::ArticulatedBody& body)
    : count(static_cast<std::size_t>(body.vertices.cols())), dofs(body.dofs()), positions(3 * count, 1.0),
      jacobians(3 * dofs * count, 1.0), gradients(3 * count), dLdx(dofs)
  {
    std::mt19937_64 rng(9);
    std::normal_distribution<double> g(0.0, 1.0);
    for (double& x : gradients)
      x = g(rng);
  }
};

void registerVertexKernels(const Robot& robot)
{
  const drb::ArticulatedBody* body = robot.body.get();
  auto work = std::make_shared<VertexWork>(*body);
  const std::size_t n = work->count;
  const SimdPath path = bestPath();
  const std::string jac = "articulated_jacobian/" + robot.name + "/", bp = "articulated_backprop/" + robot.name + "/";
  add(jac + "ours", [&robot, body, work, n](benchmark::State& st) {
    perConfiguration(st, robot, n, [&](const double* x) {
      drb::articulatedVertexJacobians(*body, drb::articulatedPose(*body, x), {}, {}, work->positions.data(),
                                      work->jacobians.data());
      benchmark::DoNotOptimize(work->jacobians.data());
    });
  });
  add(jac + "floor_write_" + pathName(path), [&robot, work, n, path](benchmark::State& st) {
    perConfiguration(st, robot, n, [&](const double*) {
      writeOnce(path, work->jacobians.data(), work->jacobians.size());
      writeOnce(path, work->positions.data(), work->positions.size());
      benchmark::DoNotOptimize(work->jacobians.data());
    });
  });
  add(bp + "ours", [&robot, body, work, n](benchmark::State& st) {
    perConfiguration(st, robot, n, [&](const double* x) {
      drb::articulatedBackprop(*body, drb::articulatedPose(*body, x), {}, work->gradients.data(), work->dLdx.data());
      benchmark::DoNotOptimize(work->dLdx.data());
    });
  });
  add(bp + "node_call", [&robot, work, n](benchmark::State& st) {
    const drb::SceneState current = robot.queries->initialState();
    perConfiguration(st, robot, n, [&](const double* x) {
      const std::vector<double> q(x, x + robot.body->dofs());
      const auto dLdx = robot.queries->backprop(current, robot.body_name, {}, work->gradients, q);
      benchmark::DoNotOptimize(dLdx.data());
    });
  });
  add(bp + "ours_kernel", [&robot, body, work, n](benchmark::State& st) {
    std::vector<drb::ArticulatedPose<double>> poses;
    for (const std::vector<double>& x : robot.states)
      poses.push_back(drb::articulatedPose(*body, x.data()));
    std::size_t i = 0;
    perConfiguration(st, robot, n, [&](const double*) {
      drb::articulatedBackprop(*body, poses[i], {}, work->gradients.data(), work->dLdx.data());
      benchmark::DoNotOptimize(work->dLdx.data());
      i = (i + 1) % poses.size();
    });
  });
  add(bp + "floor_read_" + pathName(path), [&robot, body, work, n, path](benchmark::State& st) {
    perConfiguration(st, robot, n, [&](const double*) {
      double sum = readOnce(path, body->vertices, work->gradients.data());
      benchmark::DoNotOptimize(sum);
    });
  });
}

std::string number(double value)
{
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

/// Sizes, masses and what each peer covers, then the errors.
void describe(const Robot& robot)
{
  const drb::ArticulatedBody& body = *robot.body;
  const std::string key = "articulated." + robot.name + ".";
  double mass = 0;
  for (const drb::Segment& s : body.segments)
    mass += s.mass_properties.mass;
  benchmark::AddCustomContext(key + "dofs", std::to_string(body.dofs()));
  benchmark::AddCustomContext(key + "segments", std::to_string(body.segments.size()));
  benchmark::AddCustomContext(key + "vertices", std::to_string(body.vertices.cols()));
  benchmark::AddCustomContext(key + "mass", number(mass));
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  KdlArm kdl(robot);
  double chain_mass = 0;
  for (const KDL::Segment& s : kdl.chain.segments)
    chain_mass += s.getInertia().getMass();
  benchmark::AddCustomContext(key + "kdl.chain", robot.kdl_base + ".." + robot.kdl_tip);
  benchmark::AddCustomContext(key + "kdl.joints", std::to_string(kdl.chain.getNrOfJoints()));
  benchmark::AddCustomContext(key + "kdl.mass", number(chain_mass));
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  MujocoArm mj(robot);
  double moving = 0;
  for (int b = 1; b < mj.model->nbody; ++b)
    if (mj.model->body_weldid[b] != 0)
      moving += mj.model->body_mass[b];
  benchmark::AddCustomContext(key + "mujoco.nv", std::to_string(mj.model->nv));
  benchmark::AddCustomContext(key + "mujoco.mass", number(moving));
#endif
  for (const auto& [name, error] : massMatrixErrors(robot))
    benchmark::AddCustomContext(key + "error." + name, number(error));
}
}  // namespace

int main(int argc, char** argv)
{
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
#ifdef DRB_BENCH_HAVE_MUJOCO
  mju_user_warning = [](const char*) {};
#endif
  for (const Robot& robot : robots())
  {
    describe(robot);
    registerMassMatrix(robot);
  }
  registerVertexKernels(robots()[0]);  // the Panda: every collision-mesh vertex of the body
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
