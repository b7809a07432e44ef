// The peers of one robot (body_robots.h), loaded once and shared by its
// rows and its error measurements: KDL (kdl_peer.h), MuJoCo (mujoco_peer.h)
// and Pinocchio (pinocchio_coordinates.h). A peer that is not built (its
// library missing at configure time) is null, and its rows are dropped.
// Peers keep state between calls: one thread at a time.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "body_robots.h"
#include "kdl_peer.h"
#include "mujoco_peer.h"
#include "pinocchio_coordinates.h"

namespace drb_bench
{
struct RobotPeers
{
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  std::unique_ptr<KdlArm> kdl;
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  std::unique_ptr<MujocoArm> mujoco;
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  /// Timing model (Fixed, or FreeFlyer for a floating robot), and the oracle
  /// of the errors (Fixed, or EulerZYX): the same object for a fixed base.
  std::unique_ptr<PinocchioArm> pinocchio;
  std::unique_ptr<PinocchioArm> pinocchio_oracle_floating;
  PinocchioArm& pinocchioOracle() { return pinocchio_oracle_floating ? *pinocchio_oracle_floating : *pinocchio; }
#endif
};

inline RobotPeers& peersOf(const Robot& robot)
{
  static std::map<std::string, std::unique_ptr<RobotPeers>> cache;
  std::unique_ptr<RobotPeers>& peers = cache[robot.name];
  if (!peers)
  {
    peers = std::make_unique<RobotPeers>();
#ifdef DRB_BENCH_HAVE_KDL_PARSER
    peers->kdl = std::make_unique<KdlArm>(robot);
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
    peers->mujoco = std::make_unique<MujocoArm>(robot);
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
    peers->pinocchio = std::make_unique<PinocchioArm>(robot, robot.pinocchio_timing_urdf,
                                                      robot.floating ? PinocchioRoot::FreeFlyer : PinocchioRoot::Fixed);
    if (robot.floating)
      peers->pinocchio_oracle_floating = std::make_unique<PinocchioArm>(robot, robot.urdf, PinocchioRoot::EulerZYX);
#endif
  }
  return *peers;
}

}  // namespace drb_bench
