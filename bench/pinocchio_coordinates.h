// Pinocchio (bench/pinocchio_peer.h) in a robot's coordinates
// (body_robots.h): which of Pinocchio's velocity coordinates each of ours
// drives, and the configurations of the timing loops made once, outside them.
//
// With A (nv x d) and o (nv), Pinocchio's velocity-sized values are
//   x_pin = A x + o,   v = A x',   a = A x'',
// and q = configuration(x_pin) (a continuous joint's (cos, sin), a free
// flyer's quaternion). Then M_ours = A^T M_pin A and tau_ours = A^T tau_pin
// (A(j, c) = m_j for joint j on coordinate c; mimic joints are independent
// dofs in Pinocchio). Roots:
//   fixed-base robots   PinocchioRoot::Fixed, the same URDF, every joint by name;
//   floating robot      timing: PinocchioRoot::FreeFlyer on the fixed-base
//                       URDF (Pinocchio's own model, a quaternion root: not
//                       our coordinates, so no errors from it); errors:
//                       PinocchioRoot::EulerZYX on the floating URDF, whose
//                       chain <joint>_translation, _rz, _ry, _rx is our
//                       (tx, ty, tz), psi, theta, phi, a permutation (A square).
#pragma once

#ifdef DRB_BENCH_HAVE_PINOCCHIO

#include <stdexcept>
#include <string>
#include <vector>

#include "body_robots.h"
#include "pinocchio_peer.h"

namespace drb_bench
{
using drb_pinocchio::PinocchioRobot;
using drb_pinocchio::PinocchioRoot;

/// Ends with `suffix`: the prefix before it, else "".
inline std::string prefixBefore(const std::string& name, const std::string& suffix)
{
  if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
    return name.substr(0, name.size() - suffix.size());
  return "";
}

/// The free root of a robot with exactly one (its first coordinate).
inline int onlyFreeRoot(const Robot& robot)
{
  for (std::size_t b = 0; b < robot.bodies().size(); ++b)
    if (robot.bodies()[b].hasFreeRoot())
      return static_cast<int>(robot.offsets[b]);
  throw std::runtime_error("robot " + robot.name + " has no free root for Pinocchio's free flyer");
}

struct PinocchioArm
{
  PinocchioRobot model;
  Eigen::MatrixXd A;       ///< nv x d
  Eigen::VectorXd offset;  ///< nv
  /// Per robot state: q, v, a and A tau (Pinocchio's generalized force for aba).
  std::vector<Eigen::VectorXd> q, v, a, tau;

  PinocchioArm(const Robot& robot, const std::string& urdf, PinocchioRoot root) : model(urdf, root)
  {
    const Eigen::Index d = static_cast<Eigen::Index>(robot.coordinates);
    A = Eigen::MatrixXd::Zero(model.nv(), d);
    offset = Eigen::VectorXd::Zero(model.nv());
    for (const drb_pinocchio::JointInfo& joint : model.joints())
    {
      const int iv = joint.idx_v;
      if (joint.nv == 6)  // free flyer: v = (t, then phi, theta, psi as configuration() reads them)
      {
        const int c = onlyFreeRoot(robot);
        for (int k = 0; k < 3; ++k)
          A(iv + k, c + drb::TX + k) = 1.0, A(iv + 3 + k, c + drb::PHI + k) = 1.0;
      }
      else if (const std::string chain = prefixBefore(joint.name, "_translation"); !chain.empty() && joint.nv == 3)
        for (int k = 0; k < 3; ++k)
          A(iv + k, freeRootOffset(robot, chain) + drb::TX + k) = 1.0;
      else if (joint.type == "JointModelRZ" && !prefixBefore(joint.name, "_rz").empty())
        A(iv, freeRootOffset(robot, prefixBefore(joint.name, "_rz")) + drb::PSI) = 1.0;
      else if (joint.type == "JointModelRY" && !prefixBefore(joint.name, "_ry").empty())
        A(iv, freeRootOffset(robot, prefixBefore(joint.name, "_ry")) + drb::THETA) = 1.0;
      else if (joint.type == "JointModelRX" && !prefixBefore(joint.name, "_rx").empty())
        A(iv, freeRootOffset(robot, prefixBefore(joint.name, "_rx")) + drb::PHI) = 1.0;
      else if (joint.nv == 1)
      {
        const JointSource s = jointSource(robot, joint.name);
        A(iv, s.coordinate) = s.multiplier;
        offset[iv] = s.offset;
      }
      else
        throw std::runtime_error("pinocchio: joint " + joint.name + " (" + joint.type + ") has no source");
    }
    for (const RobotState& s : robot.states)
    {
      q.push_back(configuration(s.x.data()));
      v.push_back(velocity(s.xd.data()));
      a.push_back(velocity(s.xdd.data()));
      tau.push_back(velocity(s.tau.data()));
    }
  }

  Eigen::Map<const Eigen::VectorXd> in(const double* x) const { return { x, A.cols() }; }
  /// q = configuration(A x + o).
  Eigen::VectorXd configuration(const double* x) const { return model.configuration(A * in(x) + offset); }
  /// A x' (also for accelerations and, as Pinocchio's input, forces).
  Eigen::VectorXd velocity(const double* xd) const { return A * in(xd); }
  /// Whether A is a permutation (no mimic joint): then M^-1 and x'' map back as A^T (.) A.
  bool permutation() const { return A.rows() == A.cols(); }
};

}  // namespace drb_bench

#endif  // DRB_BENCH_HAVE_PINOCCHIO
