// Rows of drb_bench_articulated for the kinematics, M(x) and dM/dx of a
// robot (body_robots.h), one configuration per iteration:
//   kinematics/<robot>/{ours, pinocchio}
//       forwardKinematics (every body) | Pinocchio forwardKinematics
//   mass_matrix/<robot>/<method>   M(x), the pose included:
//       ours            crba(model, ws, x) per body (what SceneQueries runs)
//       node_call       SceneQueries::massMatrices for one configuration of
//                       every body, answer reused (the node's whole call)
//       ours_chain_mass ours with the segments off KDL's chain massless
//                       (only where KDL's chain leaves mass out: the Panda)
//       kdl             ChainDynParam::JntToMass on the chain
//       mujoco          mj_kinematics + mj_comPos + mj_crb + mj_fullM
//       pinocchio       crba, its lower triangle filled
//   mass_matrix_derivatives/<robot>/ours   massMatrixDerivatives: all d
//       matrices dM/dx_j (the node's path for a tree)
// and for every collision-mesh vertex of a one-body robot with vertices:
//   jacobian/<robot>/{ours, floor_write_<isa>, pinocchio_joint_jacobians}
//       vertexJacobians<double> (positions and all d columns) | storing
//       the same 3 + 3d doubles per vertex once | computeJointJacobians
//       (6 x nv, per call: what a per-vertex J would start from)
//   backprop/<robot>/{ours, node_call, floor_read_<isa>}
//       vertexBackprop | SceneQueries::backpropConfigurations, one
//       configuration, by reference | reading the gradients and the vertex
//       columns once (48 B per vertex)
// Items: 1 per configuration, n per vertex row.
#include <random>

#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/mass_matrix_derivatives.h"
#include "diff_rigid_body/algorithm/vertex_backprop.h"
#include "diff_rigid_body/algorithm/vertex_jacobians.h"
#include "memory_floors.h"
#include "robot_peers.h"
#include "robot_timing.h"

namespace drb_bench
{
namespace
{
/// The robot's states as node requests: q of every body, one configuration.
std::shared_ptr<std::vector<std::vector<double>>> requests(const Robot& robot)
{
  auto q = std::make_shared<std::vector<std::vector<double>>>();
  for (const RobotState& s : robot.states)
    q->push_back(s.x);
  return q;
}

/// Whether some segment off KDL's chain has mass (then ours_chain_mass is a row).
bool kdlLeavesMassOut(const Robot& robot, const std::vector<std::string>& chain_links)
{
  for (const drb::BodyModel& body : robot.bodies())
    for (const drb::Segment& s : body.segments)
      if (s.inertia.mass > 0 && std::find(chain_links.begin(), chain_links.end(), s.link) == chain_links.end())
        return true;
  return false;
}

/// crba over every body of `bodies` at the robot's state i.
void oursMassMatrix(const Robot& robot, const std::vector<drb::BodyModel>& bodies,
                    std::vector<drb::BodyWorkspace<double>>& ws, std::size_t i)
{
  const double* x = robot.states[i].x.data();
  for (std::size_t b = 0; b < bodies.size(); ++b)
  {
    drb::crba(bodies[b], ws[b], x + robot.offsets[b]);
    benchmark::DoNotOptimize(ws[b].M.data());
  }
}

void registerMassMatrixPeers(const Robot& robot, const std::string& prefix)
{
  RobotPeers& peers = peersOf(robot);
  (void)peers;
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  KdlArm* kdl = peers.kdl.get();
  if (!robot.floating && kdlLeavesMassOut(robot, kdl->links))
    addBenchmark(prefix + "ours_chain_mass", [&robot, kdl](benchmark::State& st) {
      const std::vector<drb::BodyModel> on_chain = massOnlyIn(robot.bodies(), kdl->links);
      auto ws = workspaces<double>(on_chain);
      perState(st, robot, 1, [&](std::size_t i) { oursMassMatrix(robot, on_chain, ws, i); });
    });
  addBenchmark(prefix + "kdl", [&robot, kdl](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      kdl->massMatrix(robot.states[i].x.data());
      benchmark::DoNotOptimize(kdl->H.data.data());
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  MujocoArm* mj = peers.mujoco.get();
  addBenchmark(prefix + "mujoco", [&robot, mj](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      mj->massMatrix(robot.states[i].x.data());
      benchmark::DoNotOptimize(mj->dense.data());
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm* pin = peers.pinocchio.get();
  addBenchmark(prefix + "pinocchio", [&robot, pin](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) { benchmark::DoNotOptimize(pin->model.crba(pin->q[i]).data()); });
  });
  addBenchmark("kinematics/" + robot.name + "/pinocchio", [&robot, pin](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      pin->model.forwardKinematics(pin->q[i]);
      benchmark::ClobberMemory();
    });
  });
#endif
}

#if defined(DRB_BENCH_SIMD_PATHS)
/// The best SIMD path of this CPU for the floors.
SimdPath bestPath()
{
  for (SimdPath p : { SimdPath::avx512, SimdPath::avx2 })
    if (cpuHas(p))
      return p;
  return SimdPath::sse2;
}

/// Stores `count` doubles once with ordinary stores (the kernel does not stream).
void writeOnce(SimdPath path, double* out, std::size_t count)
{
  if (path == SimdPath::avx512)
    floors::write8(out, count, 1.0, false);
  else if (path == SimdPath::avx2)
    floors::write4(out, count, 1.0, false);
  else
    floors::write2(out, count, 1.0, false);
}
#endif

/// Outputs and gradients of every vertex of a body, allocated and touched once.
struct VertexWork
{
  std::size_t count, dofs;
  std::vector<double> positions, jacobians, gradients, dLdx;
  explicit VertexWork(const drb::BodyModel& body)
    : count(body.vertexCount()), dofs(body.coordinates), positions(3 * count, 1.0),
      jacobians(3 * dofs * count, 1.0), gradients(3 * count), dLdx(dofs)
  {
    std::mt19937_64 rng(9);
    std::normal_distribution<double> g(0.0, 1.0);
    for (double& x : gradients)
      x = g(rng);
  }
};
}  // namespace

void registerBodyRows(const Robot& robot)
{
  const std::string prefix = "mass_matrix/" + robot.name + "/";
  addBenchmark(prefix + "ours", [&robot](benchmark::State& st) {
    auto ws = workspaces<double>(robot.bodies());
    perState(st, robot, 1, [&](std::size_t i) { oursMassMatrix(robot, robot.bodies(), ws, i); });
  });
  auto q = requests(robot);
  addBenchmark(prefix + "node_call", [&robot, q](benchmark::State& st) {
    const drb::SceneState current = robot.queries->initialState();
    drb::MassMatrixAnswer answer;
    perState(st, robot, 1, [&](std::size_t i) {
      robot.queries->massMatrices(current, {}, (*q)[i], false, answer);
      benchmark::DoNotOptimize(answer.mass_matrices.data());
    });
  });
  addBenchmark("kinematics/" + robot.name + "/ours", [&robot](benchmark::State& st) {
    auto ws = workspaces<double>(robot.bodies());
    perState(st, robot, 1, [&](std::size_t i) {
      for (std::size_t b = 0; b < ws.size(); ++b)
      {
        drb::forwardKinematics(robot.bodies()[b], ws[b], robot.states[i].x.data() + robot.offsets[b]);
        benchmark::DoNotOptimize(ws[b].R.data());
      }
    });
  });
  addBenchmark("mass_matrix_derivatives/" + robot.name + "/ours", [&robot](benchmark::State& st) {
    auto ws = workspaces<double>(robot.bodies());
    std::vector<std::vector<double>> dM;
    for (const drb::BodyModel& body : robot.bodies())
      dM.emplace_back(body.coordinates * body.coordinates * body.coordinates);
    perState(st, robot, 1, [&](std::size_t i) {
      for (std::size_t b = 0; b < ws.size(); ++b)
      {
        drb::massMatrixDerivatives(robot.bodies()[b], ws[b], robot.states[i].x.data() + robot.offsets[b],
                                   dM[b].data());
        benchmark::DoNotOptimize(dM[b].data());
      }
    });
  });
  registerMassMatrixPeers(robot, prefix);
}

void registerVertexRows(const Robot& robot)
{
  if (robot.bodies().size() != 1 || robot.bodies()[0].vertexCount() == 0)
    return;
  const drb::BodyModel& body = robot.bodies()[0];
  auto work = std::make_shared<VertexWork>(body);
  const std::size_t n = work->count;
  const std::string jac = "jacobian/" + robot.name + "/", bp = "backprop/" + robot.name + "/";
  addBenchmark(jac + "ours", [&robot, &body, work, n](benchmark::State& st) {
    drb::BodyWorkspace<double> ws(body);
    const drb::JacobianColumns columns = drb::JacobianColumns::all(body);
    perState(st, robot, n, [&](std::size_t i) {
      drb::vertexJacobians<double>(body, ws, columns, {}, robot.states[i].x.data(), work->positions.data(),
                                   work->jacobians.data());
      benchmark::DoNotOptimize(work->jacobians.data());
    });
  });
#if defined(DRB_BENCH_SIMD_PATHS)
  const SimdPath path = bestPath();
  addBenchmark(jac + "floor_write_" + pathName(path), [&robot, work, n, path](benchmark::State& st) {
    perState(st, robot, n, [&](std::size_t) {
      writeOnce(path, work->jacobians.data(), work->jacobians.size());
      writeOnce(path, work->positions.data(), work->positions.size());
      benchmark::DoNotOptimize(work->jacobians.data());
    });
  });
  addBenchmark(bp + "floor_read_" + pathName(path), [&robot, &body, work, n, path](benchmark::State& st) {
    perState(st, robot, n, [&](std::size_t) {
      double sum = readFloor(path, body.vertex_columns, work->gradients.data());
      benchmark::DoNotOptimize(sum);
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm* pin = peersOf(robot).pinocchio.get();
  addBenchmark(jac + "pinocchio_joint_jacobians", [&robot, pin, n](benchmark::State& st) {
    perState(st, robot, n, [&](std::size_t i) {
      benchmark::DoNotOptimize(pin->model.computeJointJacobians(pin->q[i]).data());
    });
  });
#endif
  addBenchmark(bp + "ours", [&robot, &body, work, n](benchmark::State& st) {
    drb::BodyWorkspace<double> ws(body);
    perState(st, robot, n, [&](std::size_t i) {
      drb::vertexBackprop(body, ws, {}, work->gradients.data(), robot.states[i].x.data(), work->dLdx.data());
      benchmark::DoNotOptimize(work->dLdx.data());
    });
  });
  auto q = requests(robot);
  addBenchmark(bp + "node_call", [&robot, &body, work, n, q](benchmark::State& st) {
    const drb::SceneState current = robot.queries->initialState();
    std::vector<double> gradient;
    perState(st, robot, n, [&](std::size_t i) {
      robot.queries->backpropConfigurations(current, body.name, {}, work->gradients, (*q)[i], gradient);
      benchmark::DoNotOptimize(gradient.data());
    });
  });
}

}  // namespace drb_bench
