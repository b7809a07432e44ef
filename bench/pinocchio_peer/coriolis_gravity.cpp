// PinocchioRobot::coriolisMatrix and generalizedGravity (both from Pinocchio's rnea.hpp).
#include <pinocchio/algorithm/rnea.hpp>

#include "impl.h"

namespace drb_pinocchio
{

const Eigen::VectorXd& PinocchioRobot::generalizedGravity(const Eigen::VectorXd& q)
{
  return pinocchio::computeGeneralizedGravity(impl_->model, impl_->data, q);
}

const Eigen::MatrixXd& PinocchioRobot::coriolisMatrix(const Eigen::VectorXd& q, const Eigen::VectorXd& v)
{
  return pinocchio::computeCoriolisMatrix(impl_->model, impl_->data, q, v);
}

}  // namespace drb_pinocchio
