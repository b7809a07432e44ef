// PinocchioRobot::forwardKinematics and the poses it gives.
#include <stdexcept>

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include "impl.h"

namespace drb_pinocchio
{
namespace
{
Eigen::Isometry3d isometry(const pinocchio::SE3& m)
{
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = m.rotation();
  pose.translation() = m.translation();
  return pose;
}
}  // namespace

void PinocchioRobot::forwardKinematics(const Eigen::VectorXd& q)
{
  pinocchio::forwardKinematics(impl_->model, impl_->data, q);
}

Eigen::Isometry3d PinocchioRobot::jointPose(int id) const
{
  if (id < 0 || id >= impl_->model.njoints)
    throw std::invalid_argument("PinocchioRobot::jointPose: no joint " + std::to_string(id));
  return isometry(impl_->data.oMi[static_cast<std::size_t>(id)]);
}

Eigen::Isometry3d PinocchioRobot::linkPose(const std::string& link) const
{
  if (!impl_->model.existBodyName(link))
    throw std::invalid_argument("PinocchioRobot::linkPose: no link " + link);
  const pinocchio::Frame& frame = impl_->model.frames[impl_->model.getBodyId(link)];
  return isometry(impl_->data.oMi[frame.parentJoint] * frame.placement);
}

}  // namespace drb_pinocchio
