// drb_bench_articulated: bodies with joints (body_model.h) against KDL,
// MuJoCo and Pinocchio on the same URDFs, in one run: the Panda, the UR5,
// simple_humanoid on its fixed base and with a floating root
// (body_robots.h). The rows: bench_bodies.cpp (kinematics, M, dM/dx,
// vertex Jacobians and backprop) and bench_dynamics.cpp (inverse and
// forward dynamics and their derivatives); the errors against MPFR
// (body_errors.h), the models' sizes and masses and what each peer covers go
// into the JSON's context as "articulated.<robot>.<key>". Run by
// scripts/bench; bench/report_articulated.py writes the docs section.
#include <benchmark/benchmark.h>

#include <cstdio>

#include "body_errors.h"
#include "robot_peers.h"
#include "robot_timing.h"

namespace
{
using namespace drb_bench;

std::string number(double value)
{
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

/// Sizes, masses and what each peer covers, then the errors.
void describe(const Robot& robot)
{
  const std::string key = "articulated." + robot.name + ".";
  auto context = [&](const std::string& name, const std::string& value) {
    benchmark::AddCustomContext(key + name, value);
  };
  double mass = 0;
  std::size_t segments = 0;
  for (const drb::BodyModel& body : robot.bodies())
    mass += body.mass(), segments += body.segments.size();
  context("label", robot.label);
  context("coordinates", std::to_string(robot.coordinates));
  context("bodies", std::to_string(robot.bodies().size()));
  context("segments", std::to_string(segments));
  context("vertices", std::to_string(robot.vertexCount()));
  context("mass", number(mass));
  context("floating", robot.floating ? "1" : "0");
  RobotPeers& peers = peersOf(robot);
  (void)peers;
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  double chain_mass = 0;
  for (const KDL::Segment& s : peers.kdl->chain.segments)
    chain_mass += s.getInertia().getMass();
  context("kdl.chain", robot.kdl_base + ".." + robot.kdl_tip);
  context("kdl.joints", std::to_string(peers.kdl->chain.getNrOfJoints()));
  context("kdl.mass", number(chain_mass));
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  const mjModel* mj = peers.mujoco->model;
  double moving = 0;
  for (int b = 1; b < mj->nbody; ++b)
    if (mj->body_weldid[b] != 0)
      moving += mj->body_mass[b];
  context("mujoco.nv", std::to_string(mj->nv));
  context("mujoco.mass", number(moving));
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  context("pinocchio.nq", std::to_string(peers.pinocchio->model.nq()));
  context("pinocchio.nv", std::to_string(peers.pinocchio->model.nv()));
#endif
  context("conditioning.M", number(massMatrixConditioning(robot)));
  for (const ErrorTable& table : { bodyErrors(robot), dynamicsErrors(robot) })
    for (const auto& [name, error] : table)
      context("error." + name, number(error));
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
    registerBodyRows(robot);
    registerVertexRows(robot);
    registerDynamicsRows(robot);
    registerFrameRows(robot);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
