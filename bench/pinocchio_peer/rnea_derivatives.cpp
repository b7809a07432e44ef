// PinocchioRobot::rneaDerivatives: dtau/dq, dtau/dv (and M).
#include <pinocchio/algorithm/rnea-derivatives.hpp>

#include "impl.h"

namespace drb_pinocchio
{

RneaDerivatives PinocchioRobot::rneaDerivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                                const Eigen::VectorXd& a)
{
  pinocchio::Data& data = impl_->data;
  pinocchio::computeRNEADerivatives(impl_->model, data, q, v, a);  // M: upper triangle only
  fillLowerTriangle(data.M);
  return { data.dtau_dq, data.dtau_dv, data.M };
}

}  // namespace drb_pinocchio
