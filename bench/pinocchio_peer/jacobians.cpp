// PinocchioRobot::computeJointJacobians: every joint's columns in the world frame.
#include <pinocchio/algorithm/jacobian.hpp>

#include "impl.h"

namespace drb_pinocchio
{

const Matrix6Xd& PinocchioRobot::computeJointJacobians(const Eigen::VectorXd& q)
{
  return pinocchio::computeJointJacobians(impl_->model, impl_->data, q);
}

}  // namespace drb_pinocchio
