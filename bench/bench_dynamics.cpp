// Rows of drb_bench_articulated for the dynamics of a robot (body_robots.h;
// docs/interface.md, Version 3), one state (x, x', x'' or tau) per iteration,
// gravity gamma = (0, 0, -9.81) m/s^2 for every method:
//   inverse_dynamics/<robot>/<method>   tau = M x'' + c(x, x') + g(x)
//       ours        inverseDynamics (RNEA) per body
//       pinocchio   rnea
//       kdl         ChainIdSolver_RNE::CartToJnt on KDL's chain
//       mujoco      mj_kinematics + mj_comPos + mj_comVel + mj_rne
//   inverse_dynamics_derivatives/<robot>/{ours, pinocchio}
//       dtau/dx and dtau/dx' together: inverseDynamicsDerivatives |
//       computeRNEADerivatives (also gives M)
//   forward_dynamics/<robot>/{ours, pinocchio}
//       x'' = M^-1 (tau - c - g): forwardDynamics (CRBA, RNEA, M = L^T D L
//       along the tree) | aba
//   forward_dynamics_derivatives/<robot>/{ours, pinocchio}
//       dx''/dx, dx''/dx', M^-1: forwardDynamicsDerivatives |
//       computeABADerivatives
// Pinocchio's floating humanoid is its own FreeFlyer model (pinocchio_coordinates.h).
// Items: 1 per state.
#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "diff_rigid_body/algorithm/rnea.h"
#include "diff_rigid_body/algorithm/rnea_derivatives.h"
#include "robot_peers.h"
#include "robot_timing.h"

namespace drb_bench
{
namespace
{
/// Per body: the outputs of the derivative rows, sized once.
struct DerivativeOutputs
{
  std::vector<Eigen::MatrixXd> dx, dxd, inverse_mass;
  std::vector<double> values;  ///< tau or x'' of the whole robot

  explicit DerivativeOutputs(const Robot& robot) : values(robot.coordinates)
  {
    for (const drb::BodyModel& body : robot.bodies())
    {
      const Eigen::Index d = static_cast<Eigen::Index>(body.coordinates);
      dx.emplace_back(d, d);
      dxd.emplace_back(d, d);
      inverse_mass.emplace_back(d, d);
    }
  }
};

void registerDynamicsPeers(const Robot& robot)
{
  RobotPeers& peers = peersOf(robot);
  (void)peers;
  const std::string id = "inverse_dynamics/" + robot.name + "/";
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  KdlArm* kdl = peers.kdl.get();
  addBenchmark(id + "kdl", [&robot, kdl](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      const RobotState& s = robot.states[i];
      kdl->inverseDynamics(s.x.data(), s.xd.data(), s.xdd.data());
      benchmark::DoNotOptimize(kdl->tau.data.data());
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  MujocoArm* mj = peers.mujoco.get();
  addBenchmark(id + "mujoco", [&robot, mj](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      const RobotState& s = robot.states[i];
      mj->inverseDynamics(s.x.data(), s.xd.data(), s.xdd.data());
      benchmark::DoNotOptimize(mj->tau.data());
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm* pin = peers.pinocchio.get();
  addBenchmark(id + "pinocchio", [&robot, pin](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      benchmark::DoNotOptimize(pin->model.rnea(pin->q[i], pin->v[i], pin->a[i]).data());
    });
  });
  addBenchmark("inverse_dynamics_derivatives/" + robot.name + "/pinocchio", [&robot, pin](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      benchmark::DoNotOptimize(pin->model.rneaDerivatives(pin->q[i], pin->v[i], pin->a[i]).dtau_dq.data());
    });
  });
  addBenchmark("forward_dynamics/" + robot.name + "/pinocchio", [&robot, pin](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      benchmark::DoNotOptimize(pin->model.aba(pin->q[i], pin->v[i], pin->tau[i]).data());
    });
  });
  addBenchmark("forward_dynamics_derivatives/" + robot.name + "/pinocchio", [&robot, pin](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      benchmark::DoNotOptimize(pin->model.abaDerivatives(pin->q[i], pin->v[i], pin->tau[i]).ddq_dq.data());
    });
  });
#endif
}
}  // namespace

void registerDynamicsRows(const Robot& robot)
{
  const Eigen::Vector3d gravity = drb::standardGravity();
  addBenchmark("inverse_dynamics/" + robot.name + "/ours", [&robot, gravity](benchmark::State& st) {
    auto ws = workspaces<double>(robot.bodies());
    std::vector<double> tau(robot.coordinates);
    perState(st, robot, 1, [&](std::size_t i) {
      const RobotState& s = robot.states[i];
      for (std::size_t b = 0; b < ws.size(); ++b)
      {
        const std::size_t o = robot.offsets[b];
        drb::inverseDynamics(robot.bodies()[b], ws[b], s.x.data() + o, s.xd.data() + o, s.xdd.data() + o, gravity,
                             tau.data() + o);
      }
      benchmark::DoNotOptimize(tau.data());
    });
  });
  addBenchmark("inverse_dynamics_derivatives/" + robot.name + "/ours", [&robot, gravity](benchmark::State& st) {
    auto ws = workspaces<double>(robot.bodies());
    DerivativeOutputs out(robot);
    perState(st, robot, 1, [&](std::size_t i) {
      const RobotState& s = robot.states[i];
      for (std::size_t b = 0; b < ws.size(); ++b)
      {
        const std::size_t o = robot.offsets[b];
        drb::inverseDynamicsDerivatives(robot.bodies()[b], ws[b], s.x.data() + o, s.xd.data() + o, s.xdd.data() + o,
                                        gravity, out.dx[b], out.dxd[b]);
        benchmark::DoNotOptimize(out.dx[b].data());
      }
    });
  });
  addBenchmark("forward_dynamics/" + robot.name + "/ours", [&robot, gravity](benchmark::State& st) {
    auto ws = workspaces<double>(robot.bodies());
    std::vector<double> xdd(robot.coordinates);
    perState(st, robot, 1, [&](std::size_t i) {
      const RobotState& s = robot.states[i];
      for (std::size_t b = 0; b < ws.size(); ++b)
      {
        const std::size_t o = robot.offsets[b];
        benchmark::DoNotOptimize(drb::forwardDynamics(robot.bodies()[b], ws[b], s.x.data() + o, s.xd.data() + o,
                                                      s.tau.data() + o, gravity, xdd.data() + o));
      }
      benchmark::DoNotOptimize(xdd.data());
    });
  });
  addBenchmark("forward_dynamics_derivatives/" + robot.name + "/ours", [&robot, gravity](benchmark::State& st) {
    auto ws = workspaces<double>(robot.bodies());
    DerivativeOutputs out(robot);
    perState(st, robot, 1, [&](std::size_t i) {
      const RobotState& s = robot.states[i];
      for (std::size_t b = 0; b < ws.size(); ++b)
      {
        const std::size_t o = robot.offsets[b];
        benchmark::DoNotOptimize(drb::forwardDynamicsDerivatives(robot.bodies()[b], ws[b], s.x.data() + o,
                                                                 s.xd.data() + o, s.tau.data() + o, gravity,
                                                                 out.values.data() + o, out.dx[b], out.dxd[b],
                                                                 out.inverse_mass[b]));
      }
      benchmark::DoNotOptimize(out.values.data());
    });
  });
  registerDynamicsPeers(robot);
}

}  // namespace drb_bench
