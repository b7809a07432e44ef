// PinocchioRobot: loading (URDF -> pinocchio::Model, the EulerZYX oracle
// root), joint bookkeeping, configurations, gravity. No dynamics algorithm.
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#include "impl.h"

namespace drb_pinocchio
{
namespace
{
using Visitor = pinocchio::urdf::details::UrdfVisitor<double, 0, pinocchio::JointCollectionDefaultTpl>;

/// Pinocchio's URDF visitor, except that a free body is the EulerZYX chain
/// (JointModelTranslation, RZ, RY, RX; identity rotations) with the floating
/// link's frame at -com_offset in the RX joint's frame, so that the chain's
/// translation is the floating segment's COM.
class EulerZYXVisitor : public Visitor
{
public:
  using Visitor::addJointAndBody;

  /// chain_at_root: the URDF has no `floating` joint, so the root link floats.
  /// com_offsets: c per floating link (zeros on the first pass).
  EulerZYXVisitor(pinocchio::Model& m, bool chain_at_root, std::map<std::string, Eigen::Vector3d> com_offsets)
    : Visitor(m), chain_at_root_(chain_at_root), com_offsets_(std::move(com_offsets))
  {
  }

  /// (floating link, joint id of its RX) in the order the chains were added.
  std::vector<std::pair<std::string, pinocchio::JointIndex>> chains;

  void addRootJoint(const Inertia& Y, const std::string& body_name) override
  {
    if (chain_at_root_)
      addChain(0, "root_joint", Y, body_name);
    else
      Visitor::addRootJoint(Y, body_name);
  }

  void addJointAndBody(JointType type, const Vector3& axis, const pinocchio::FrameIndex& parentFrameId,
                       const SE3& placement, const std::string& joint_name, const Inertia& Y,
                       const SE3& frame_placement, const std::string& body_name, const VectorConstRef& max_effort,
                       const VectorConstRef& max_velocity, const VectorConstRef& min_config,
                       const VectorConstRef& max_config, const VectorConstRef& friction, const VectorConstRef& damping,
                       const boost::optional<MimicInfo_>& mimic_info = boost::none) override
  {
    if (type == Base::FLOATING)
    {
      // The URDF origin of a floating joint is the body's initial pose in
      // this project, not a placement: the chain starts at the parent link's frame.
      addChain(parentFrameId, joint_name, Y, body_name);
      return;
    }
    Visitor::addJointAndBody(type, axis, parentFrameId, placement, joint_name, Y, frame_placement, body_name,
                             max_effort, max_velocity, min_config, max_config, friction, damping, mimic_info);
  }

private:
  void addChain(pinocchio::FrameIndex parent_frame_id, const std::string& name, const Inertia& Y,
                const std::string& body_name)
  {
    const pinocchio::Frame parent_frame = model.frames[parent_frame_id];  // a copy: addJointFrame reallocates
    pinocchio::JointIndex j = model.addJoint(parent_frame.parentJoint, pinocchio::JointModelTranslation(),
                                             parent_frame.placement, name + "_translation");
    pinocchio::FrameIndex f = model.addJointFrame(j, static_cast<int>(parent_frame_id));
    j = model.addJoint(j, pinocchio::JointModelRZ(), SE3::Identity(), name + "_rz");
    f = model.addJointFrame(j, static_cast<int>(f));
    j = model.addJoint(j, pinocchio::JointModelRY(), SE3::Identity(), name + "_ry");
    f = model.addJointFrame(j, static_cast<int>(f));
    j = model.addJoint(j, pinocchio::JointModelRX(), SE3::Identity(), name + "_rx");
    f = model.addJointFrame(j, static_cast<int>(f));
    const auto c = com_offsets_.find(body_name);
    const Vector3 offset = c == com_offsets_.end() ? Vector3::Zero() : Vector3(c->second);
    // The link frame (and so every link below it) at -c in the RX frame.
    appendBodyToJoint(f, Y, SE3(SE3::Matrix3::Identity(), -offset), body_name);
    chains.emplace_back(body_name, j);
  }

  bool chain_at_root_;
  std::map<std::string, Eigen::Vector3d> com_offsets_;
};

bool hasFloatingJoint(const urdf::ModelInterface& urdf)
{
  for (const auto& joint : urdf.joints_)
    if (joint.second && joint.second->type == urdf::Joint::FLOATING)
      return true;
  return false;
}

}  // namespace

PinocchioRobot::PinocchioRobot(const std::string& urdf_file, PinocchioRoot root)
{
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDFFile(urdf_file);
  if (!urdf)
    throw std::invalid_argument("PinocchioRobot: " + urdf_file + " is not a valid URDF file");

  pinocchio::Model model;
  std::vector<FloatingBody> floating;
  switch (root)
  {
    case PinocchioRoot::Fixed:
      pinocchio::urdf::buildModel(urdf, model);  // mimic = false: mimic joints are independent dofs
      break;
    case PinocchioRoot::FreeFlyer:
      pinocchio::urdf::buildModel(urdf, pinocchio::JointModelFreeFlyer(), model);
      break;
    case PinocchioRoot::EulerZYX:
    {
      // Pass 1 finds each floating segment's COM c (the lever of the composite
      // inertia on its RX joint, fixed children included); pass 2 puts the
      // chain there.
      const bool chain_at_root = !hasFloatingJoint(*urdf);
      std::map<std::string, Eigen::Vector3d> com_offsets;
      {
        pinocchio::Model first;
        EulerZYXVisitor visitor(first, chain_at_root, {});
        pinocchio::urdf::details::parseRootTree(urdf.get(), visitor, false);
        for (const auto& chain : visitor.chains)
          com_offsets[chain.first] = first.inertias[chain.second].lever();
      }
      EulerZYXVisitor visitor(model, chain_at_root, com_offsets);
      pinocchio::urdf::details::parseRootTree(urdf.get(), visitor, false);
      for (const auto& chain : visitor.chains)
      {
        FloatingBody body;
        body.link = chain.first;
        body.idx_q = model.joints[chain.second].idx_q() - 3;  // the translation's first coordinate
        body.com_offset = com_offsets[chain.first];
        floating.push_back(body);
      }
      break;
    }
  }

  impl_ = std::make_unique<Impl>(std::move(model), root);
  impl_->floating = std::move(floating);
  const pinocchio::Model& m = impl_->model;
  for (pinocchio::JointIndex j = 1; j < static_cast<pinocchio::JointIndex>(m.njoints); ++j)
  {
    JointInfo info;
    info.name = m.names[j];
    info.type = m.joints[j].shortname();
    info.id = static_cast<int>(j);
    info.parent = static_cast<int>(m.parents[j]);
    info.idx_q = m.joints[j].idx_q();
    info.nq = m.joints[j].nq();
    info.idx_v = m.joints[j].idx_v();
    info.nv = m.joints[j].nv();
    const urdf::JointConstSharedPtr joint = urdf->getJoint(info.name);
    if (joint && joint->mimic)
    {
      info.mimic = joint->mimic->joint_name;
      info.multiplier = joint->mimic->multiplier;
      info.offset = joint->mimic->offset;
    }
    impl_->joints.push_back(info);
  }
}

PinocchioRobot::~PinocchioRobot() = default;
PinocchioRobot::PinocchioRobot(PinocchioRobot&&) noexcept = default;
PinocchioRobot& PinocchioRobot::operator=(PinocchioRobot&&) noexcept = default;

int PinocchioRobot::nq() const { return impl_->model.nq; }
int PinocchioRobot::nv() const { return impl_->model.nv; }
PinocchioRoot PinocchioRobot::root() const { return impl_->root; }
const std::vector<JointInfo>& PinocchioRobot::joints() const { return impl_->joints; }
const std::vector<FloatingBody>& PinocchioRobot::floatingBodies() const { return impl_->floating; }

int PinocchioRobot::velocityIndex(const std::string& name) const
{
  for (const JointInfo& joint : impl_->joints)
    if (joint.name == name)
      return joint.idx_v;
  return -1;
}

Eigen::VectorXd PinocchioRobot::neutral() const { return pinocchio::neutral(impl_->model); }

Eigen::VectorXd PinocchioRobot::configuration(const Eigen::VectorXd& x) const
{
  if (x.size() != nv())
    throw std::invalid_argument("PinocchioRobot::configuration: x has " + std::to_string(x.size()) +
                                " values, nv is " + std::to_string(nv()));
  Eigen::VectorXd q = neutral();
  for (const JointInfo& joint : impl_->joints)
  {
    if (joint.nq == joint.nv)
      q.segment(joint.idx_q, joint.nq) = x.segment(joint.idx_v, joint.nv);
    else if (joint.nq == 2 && joint.nv == 1)  // continuous: (cos, sin)
      q.segment<2>(joint.idx_q) << std::cos(x[joint.idx_v]), std::sin(x[joint.idx_v]);
    else if (joint.nq == 7 && joint.nv == 6)  // free flyer: position, quaternion (x, y, z, w)
    {
      const double phi = x[joint.idx_v + 3], theta = x[joint.idx_v + 4], psi = x[joint.idx_v + 5];
      const Eigen::Quaterniond r = Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX());
      q.segment<3>(joint.idx_q) = x.segment<3>(joint.idx_v);
      q.segment<4>(joint.idx_q + 3) = r.coeffs();
    }
    else
      throw std::invalid_argument("PinocchioRobot::configuration: joint " + joint.name + " (" + joint.type +
                                  ") has no such mapping");
  }
  return q;
}

void PinocchioRobot::setGravity(const Eigen::Vector3d& g) { impl_->model.gravity.linear(g); }
Eigen::Vector3d PinocchioRobot::gravity() const { return impl_->model.gravity.linear(); }

}  // namespace drb_pinocchio
