// PinocchioRobot::rnea: inverse dynamics (recursive Newton-Euler).
#include <pinocchio/algorithm/rnea.hpp>

#include "impl.h"

namespace drb_pinocchio
{

const Eigen::VectorXd& PinocchioRobot::rnea(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                            const Eigen::VectorXd& a)
{
  return pinocchio::rnea(impl_->model, impl_->data, q, v, a);
}

}  // namespace drb_pinocchio
