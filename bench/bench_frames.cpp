// Rows of drb_bench_articulated for a link frame and the centre of mass
// (docs/interface.md, Version 4), one configuration per iteration. The frame
// is the tip of the robot's KDL chain (the Panda's panda_leftfinger, the UR5's
// wrist_3_link, the humanoid's l_wrist), in LOCAL_WORLD_ALIGNED:
//   frame_jacobian/<robot>/<method>   its pose and 6 x d Jacobian, the pose of
//       every supporting link included
//       ours        forwardKinematicsOf (the frame's path) + frameJacobian on
//                   the body that holds it, as SceneQueries::frameJacobians runs
//       node_call   SceneQueries::frameJacobians for that frame, one
//                   configuration, answer reused (the node's whole call)
//       pinocchio   computeFrameJacobian
//       kdl         ChainJntToJacSolver::JntToJac on its chain
//       mujoco      mj_kinematics + mj_comPos + mj_jacBody
//   com_jacobian/<robot>/<method>   c and dc/dx (one-body robots)
//       ours        centerOfMass
//       pinocchio   jacobianCenterOfMass
//       mujoco      mj_kinematics + mj_comPos + mj_jacSubtreeCom of the body's root
// Items: 1 per configuration.
#include "diff_rigid_body/algorithm/frame_jacobians.h"
#include "diff_rigid_body/algorithm/kinematics.h"
#include "robot_peers.h"
#include "robot_timing.h"

#ifdef DRB_BENCH_HAVE_KDL_PARSER
#include <kdl/chainjnttojacsolver.hpp>
#endif

namespace drb_bench
{
namespace
{
/// The body that holds link `name`, and the link's index in it.
std::pair<std::size_t, std::size_t> linkOf(const Robot& robot, const std::string& name)
{
  for (std::size_t b = 0; b < robot.bodies().size(); ++b)
    for (std::size_t l = 0; l < robot.bodies()[b].links.size(); ++l)
      if (robot.bodies()[b].links[l].name == name)
        return { b, l };
  throw std::runtime_error("bench_frames: no link " + name + " in " + robot.name);
}

void registerFramePeers(const Robot& robot, const std::string& frame)
{
  RobotPeers& peers = peersOf(robot);
  (void)peers;
  const std::string id = "frame_jacobian/" + robot.name + "/";
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  KdlArm* kdl = peers.kdl.get();
  addBenchmark(id + "kdl", [&robot, kdl](benchmark::State& st) {
    KDL::ChainJntToJacSolver solver(kdl->chain);
    KDL::Jacobian J(kdl->chain.getNrOfJoints());
    perState(st, robot, 1, [&](std::size_t i) {
      kdl->setState(robot.states[i].x.data(), nullptr, nullptr);
      solver.JntToJac(kdl->q, J);
      benchmark::DoNotOptimize(J.data.data());
    });
  });
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  MujocoArm* mj = peers.mujoco.get();
  const int body = mj_name2id(mj->model, mjOBJ_BODY, frame.c_str());
  addBenchmark(id + "mujoco", [&robot, mj, body](benchmark::State& st) {
    std::vector<mjtNum> jacp(static_cast<std::size_t>(3 * mj->model->nv)), jacr(jacp.size());
    perState(st, robot, 1, [&](std::size_t i) {
      mj->setState(robot.states[i].x.data(), nullptr, nullptr);
      mj_kinematics(mj->model, mj->data);
      mj_comPos(mj->model, mj->data);
      mj_jacBody(mj->model, mj->data, jacp.data(), jacr.data(), body);
      benchmark::DoNotOptimize(jacp.data());
    });
  });
  if (robot.bodies().size() == 1)
  {
    const int root = mj_name2id(mj->model, mjOBJ_BODY, robot.bodies()[0].name.c_str());
    addBenchmark("com_jacobian/" + robot.name + "/mujoco", [&robot, mj, root](benchmark::State& st) {
      std::vector<mjtNum> jacp(static_cast<std::size_t>(3 * mj->model->nv));
      perState(st, robot, 1, [&](std::size_t i) {
        mj->setState(robot.states[i].x.data(), nullptr, nullptr);
        mj_kinematics(mj->model, mj->data);
        mj_comPos(mj->model, mj->data);
        mj_jacSubtreeCom(mj->model, mj->data, jacp.data(), root);
        benchmark::DoNotOptimize(jacp.data());
      });
    });
  }
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm* pin = peers.pinocchio.get();
  const std::size_t pin_frame = pin->model.frameOf(frame);
  addBenchmark(id + "pinocchio", [&robot, pin, pin_frame](benchmark::State& st) {
    perState(st, robot, 1, [&](std::size_t i) {
      benchmark::DoNotOptimize(pin->model.computeFrameJacobian(pin->q[i], pin_frame, 2).data());
    });
  });
  if (robot.bodies().size() == 1)
    addBenchmark("com_jacobian/" + robot.name + "/pinocchio", [&robot, pin](benchmark::State& st) {
      perState(st, robot, 1,
               [&](std::size_t i) { benchmark::DoNotOptimize(pin->model.jacobianCenterOfMass(pin->q[i]).data()); });
    });
#endif
}
}  // namespace

void registerFrameRows(const Robot& robot)
{
  const auto [b, link] = linkOf(robot, robot.kdl_tip);
  const drb::BodyModel& body = robot.bodies()[b];
  const std::size_t offset = robot.offsets[b], d = body.coordinates;
  addBenchmark("frame_jacobian/" + robot.name + "/ours", [&robot, &body, link, offset, d](benchmark::State& st) {
    drb::BodyWorkspace<double> ws(body);
    std::vector<double> pose(12), J(6 * d);
    std::vector<char> needed(body.segments.size(), 0);
    drb::markSupport(body, link, needed);
    perState(st, robot, 1, [&](std::size_t i) {
      drb::forwardKinematicsOf(body, ws, robot.states[i].x.data() + offset, needed);
      drb::frameJacobian(body, ws, link, drb::FrameReference::LocalWorldAligned, pose.data(), J.data(), nullptr);
      benchmark::DoNotOptimize(J.data());
    });
  });
  addBenchmark("frame_jacobian/" + robot.name + "/node_call", [&robot, &body, offset, d](benchmark::State& st) {
    const drb::SceneState current = robot.queries->initialState();
    drb::FrameJacobianAnswer answer;
    std::vector<std::vector<double>> q;
    for (const RobotState& s : robot.states)
      q.emplace_back(s.x.data() + offset, s.x.data() + offset + d);
    const std::vector<std::string> frames{ robot.kdl_tip };
    perState(st, robot, 1, [&](std::size_t i) {
      robot.queries->frameJacobians(current, body.name, frames, q[i], {}, 2, false, answer);
      benchmark::DoNotOptimize(answer.jacobians.data());
    });
  });
  if (robot.bodies().size() == 1)
    addBenchmark("com_jacobian/" + robot.name + "/ours", [&robot, &body, d](benchmark::State& st) {
      drb::BodyWorkspace<double> ws(body);
      std::vector<double> com(3), J(3 * d);
      perState(st, robot, 1, [&](std::size_t i) {
        drb::centerOfMass(body, ws, robot.states[i].x.data(), nullptr, com.data(), J.data(), nullptr);
        benchmark::DoNotOptimize(J.data());
      });
    });
  registerFramePeers(robot, robot.kdl_tip);
}

}  // namespace drb_bench
