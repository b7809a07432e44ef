// PinocchioRobot::aba: forward dynamics (articulated-body algorithm).
#include <pinocchio/algorithm/aba.hpp>

#include "impl.h"

namespace drb_pinocchio
{

const Eigen::VectorXd& PinocchioRobot::aba(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                           const Eigen::VectorXd& tau)
{
  return pinocchio::aba(impl_->model, impl_->data, q, v, tau);
}

}  // namespace drb_pinocchio
