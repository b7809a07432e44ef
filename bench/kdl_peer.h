// KDL as a peer of drb_bench_articulated: the chain kdl_base .. kdl_tip of
// the tree kdl_parser builds from the robot's URDF (body_robots.h), with
//   M:    ChainDynParam::JntToMass
//   tau:  ChainIdSolver_RNE::CartToJnt (no external wrenches), gravity
//         gamma = (0, 0, -9.81) m/s^2 as ours (standardGravity)
// KDL has no floating joint and no tree dynamics: it covers the chain only
// (the Panda without its right finger, the humanoid's longest chain: waist,
// chest and left arm, 10 of 29 joints), on a fixed base.
#pragma once

#ifdef DRB_BENCH_HAVE_KDL_PARSER

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include "body_robots.h"

namespace drb_bench
{
struct KdlArm
{
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainDynParam> dyn;
  std::unique_ptr<KDL::ChainIdSolver_RNE> rne;  ///< holds a reference to `chain`: KdlArm never moves
  KDL::JntArray q, qd, qdd, tau;
  KDL::Wrenches no_wrenches;
  KDL::JntSpaceInertiaMatrix H;
  std::vector<JointSource> sources;  ///< per chain joint
  std::vector<std::string> links;    ///< the chain's segments (links)

  explicit KdlArm(const Robot& robot)
  {
    KDL::Tree tree;
    if (!kdl_parser::treeFromString(readText(robot.kdl_urdf), tree) ||
        !tree.getChain(robot.kdl_base, robot.kdl_tip, chain))
      throw std::runtime_error("kdl_parser: no chain " + robot.kdl_base + ".." + robot.kdl_tip);
    for (const KDL::Segment& segment : chain.segments)
    {
      links.push_back(segment.getName());
      if (segment.getJoint().getType() != KDL::Joint::None)
        sources.push_back(jointSource(robot, segment.getJoint().getName()));
    }
    const KDL::Vector gravity(0.0, 0.0, -9.81);
    dyn = std::make_unique<KDL::ChainDynParam>(chain, gravity);
    rne = std::make_unique<KDL::ChainIdSolver_RNE>(chain, gravity);
    const unsigned n = chain.getNrOfJoints();
    q.resize(n), qd.resize(n), qdd.resize(n), tau.resize(n), H.resize(n);
    no_wrenches.assign(chain.getNrOfSegments(), KDL::Wrench::Zero());
  }
  KdlArm(const KdlArm&) = delete;
  KdlArm& operator=(const KdlArm&) = delete;

  /// Joint values m x[c] + o, rates m x'[c], accelerations m x''[c].
  void setState(const double* x, const double* xd, const double* xdd)
  {
    for (std::size_t j = 0; j < sources.size(); ++j)
    {
      const JointSource& s = sources[j];
      q(j) = s.multiplier * x[s.coordinate] + s.offset;
      if (xd)
        qd(j) = s.multiplier * xd[s.coordinate], qdd(j) = s.multiplier * xdd[s.coordinate];
    }
  }
  void massMatrix(const double* x)
  {
    setState(x, nullptr, nullptr);
    dyn->JntToMass(q, H);
  }
  void inverseDynamics(const double* x, const double* xd, const double* xdd)
  {
    setState(x, xd, xdd);
    rne->CartToJnt(q, qd, qdd, no_wrenches, tau);
  }
  /// A (joints x d): A(j, c_j) = m_j.
  Eigen::MatrixXd selection(std::size_t d) const
  {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(sources.size()), static_cast<Eigen::Index>(d));
    for (std::size_t j = 0; j < sources.size(); ++j)
      A(static_cast<Eigen::Index>(j), sources[j].coordinate) = sources[j].multiplier;
    return A;
  }
  /// A^T H A: the last M in our coordinates (d x d).
  Eigen::MatrixXd massMatrixInCoordinates(std::size_t d) const
  {
    const Eigen::MatrixXd A = selection(d);
    return A.transpose() * H.data * A;
  }
  /// A^T tau: the last tau in our coordinates (d).
  Eigen::VectorXd tauInCoordinates(std::size_t d) const { return selection(d).transpose() * tau.data; }
};

}  // namespace drb_bench

#endif  // DRB_BENCH_HAVE_KDL_PARSER
