// PinocchioRobot::abaDerivatives: ddq/dq, ddq/dv and M^-1.
#include <pinocchio/algorithm/aba-derivatives.hpp>

#include "impl.h"

namespace drb_pinocchio
{

AbaDerivatives PinocchioRobot::abaDerivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                              const Eigen::VectorXd& tau)
{
  pinocchio::Data& data = impl_->data;
  pinocchio::computeABADerivatives(impl_->model, data, q, v, tau);  // Minv: both triangles
  return { data.ddq_dq, data.ddq_dv, data.Minv };
}

}  // namespace drb_pinocchio
