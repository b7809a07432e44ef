// PinocchioRobot::crba: the joint-space inertia matrix (composite rigid body algorithm).
#include <pinocchio/algorithm/crba.hpp>

#include "impl.h"

namespace drb_pinocchio
{

const Eigen::MatrixXd& PinocchioRobot::crba(const Eigen::VectorXd& q)
{
  pinocchio::crba(impl_->model, impl_->data, q);  // upper triangle only
  fillLowerTriangle(impl_->data.M);
  return impl_->data.M;
}

}  // namespace drb_pinocchio
