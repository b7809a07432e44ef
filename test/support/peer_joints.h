// The dynamics fixtures by name and how a peer's joint maps to our
// coordinates, for the tests against KDL and MuJoCo
// (test_dynamics_kdl_mujoco.cpp, test_frames_kdl_mujoco.cpp).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <mujoco/mujoco.h>
#include <urdf_parser/urdf_parser.h>

#include "dynamics_fixtures.h"

namespace drb_test
{
namespace peers
{
inline const dynamics::DynamicsBody& fixture(const std::string& name)
{
  for (const auto& f : dynamics::dynamicsBodies())
    if (f.name == name)
      return f;
  throw std::runtime_error("no fixture " + name);
}

/// The URDF file and chain tip of a fixed-base fixture.
inline const articulated::Fixture& spec(const std::string& name)
{
  static const std::vector<articulated::Fixture> all = articulated::fixedBaseFixtures();
  for (const auto& f : all)
    if (name == f.name)
      return f;
  throw std::runtime_error("no fixed-base fixture " + name);
}

/// x index, multiplier and offset of the 1-dof joint `joint` of `model`: the
/// peer's joint value is multiplier x[coordinate] + offset (mimic joints too).
inline bool coordinateOf(const diff_rigid_body::BodyModel& model, const std::string& joint, int& coordinate,
                         double& multiplier, double& offset)
{
  for (const diff_rigid_body::Segment& segment : model.segments)
    if (segment.joint == joint && segment.joint_type != diff_rigid_body::JointType::Free)
    {
      const diff_rigid_body::Dof& dof = model.dofs[static_cast<std::size_t>(segment.first_dof)];
      coordinate = dof.coordinate;
      multiplier = dof.multiplier;
      offset = segment.offset;
      return true;
    }
  return false;
}
/// KDL's chain of a fixed-base fixture: from the body's static base link to
/// its tip (kdl_parser's tree of the URDF), and the base's axes in the fixed
/// frame (KDL answers in the base's).
struct KdlChain
{
  KDL::Chain chain;
  std::string base;
  Eigen::Matrix3d R_base = Eigen::Matrix3d::Identity();
};

inline KdlChain kdlChain(const dynamics::DynamicsBody& f)
{
  const auto urdf_model = ::urdf::parseURDFFile(spec(f.name).path);
  KDL::Tree tree;
  KdlChain out;
  if (!urdf_model || !kdl_parser::treeFromUrdfModel(*urdf_model, tree))
    throw std::runtime_error("kdl_parser: cannot read " + spec(f.name).path);
  out.base = urdf_model->getLink(f.model().name)->getParent()->name;
  if (!tree.getChain(out.base, spec(f.name).tip, out.chain))
    throw std::runtime_error("kdl_parser: no chain " + out.base + ".." + spec(f.name).tip);
  for (const diff_rigid_body::StaticLink& link : f.scene.static_links)
    if (link.name == out.base)
      out.R_base = link.pose_in_fixed_frame.linear();
  return out;
}

/// MuJoCo's joints in our coordinates: its dof i is A.row(i) x + offset[i],
/// its position at qpos[qpos_of[i]] (MuJoCo ignores <mimic>).
struct MujocoJoints
{
  Eigen::MatrixXd A;
  Eigen::VectorXd offset;
  std::vector<int> qpos_of;
};

inline MujocoJoints mujocoJoints(const mjModel& mm, const diff_rigid_body::BodyModel& model)
{
  MujocoJoints out{ Eigen::MatrixXd::Zero(mm.nv, static_cast<Eigen::Index>(model.coordinates)),
                    Eigen::VectorXd::Zero(mm.nv), std::vector<int>(static_cast<std::size_t>(mm.nv)) };
  for (int j = 0; j < mm.njnt; ++j)
  {
    int c = -1;
    double multiplier = 1, joint_offset = 0;
    if (!coordinateOf(model, mj_id2name(&mm, mjOBJ_JOINT, j), c, multiplier, joint_offset))
      throw std::runtime_error(std::string("MuJoCo joint ") + mj_id2name(&mm, mjOBJ_JOINT, j) + " is not ours");
    out.A(mm.jnt_dofadr[j], c) = multiplier;
    out.offset[mm.jnt_dofadr[j]] = joint_offset;
    out.qpos_of[static_cast<std::size_t>(mm.jnt_dofadr[j])] = mm.jnt_qposadr[j];
  }
  return out;
}
}  // namespace peers
}  // namespace drb_test
