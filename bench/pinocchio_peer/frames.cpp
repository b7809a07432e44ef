// PinocchioRobot::frameJacobian and centerOfMass: a link frame's Jacobian and
// classical acceleration, the centre of mass and its Jacobian.
#include <stdexcept>

#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>

#include "impl.h"

namespace drb_pinocchio
{
namespace
{
pinocchio::ReferenceFrame referenceFrame(int reference)
{
  switch (reference)
  {
    case 0:
      return pinocchio::WORLD;
    case 1:
      return pinocchio::LOCAL;
    case 2:
      return pinocchio::LOCAL_WORLD_ALIGNED;
    default:
      throw std::invalid_argument("PinocchioRobot::frameJacobian: reference " + std::to_string(reference));
  }
}

/// A buffer of Impl's lifetime for the results (thread-unsafe, as the robot).
template <typename Matrix>
Matrix& buffer()
{
  static thread_local Matrix m;
  return m;
}
}  // namespace

FrameJacobian PinocchioRobot::frameJacobian(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                            const std::string& link, int reference)
{
  if (!impl_->model.existBodyName(link))
    throw std::invalid_argument("PinocchioRobot::frameJacobian: no link " + link);
  const auto frame = impl_->model.getBodyId(link);
  const pinocchio::ReferenceFrame rf = referenceFrame(reference);
  Matrix6Xd& J = buffer<Matrix6Xd>();
  J.setZero(6, impl_->model.nv);
  pinocchio::computeFrameJacobian(impl_->model, impl_->data, q, frame, rf, J);
  pinocchio::forwardKinematics(impl_->model, impl_->data, q, v, Eigen::VectorXd::Zero(impl_->model.nv));
  const pinocchio::Motion a = pinocchio::getFrameClassicalAcceleration(impl_->model, impl_->data, frame, rf);
  return { J, a.toVector() };
}

CenterOfMass PinocchioRobot::centerOfMass(const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                          const std::string& joint)
{
  if (!impl_->model.existJointName(joint))
    throw std::invalid_argument("PinocchioRobot::centerOfMass: no joint " + joint);
  const auto id = impl_->model.getJointId(joint);
  Eigen::Matrix3Xd& J = buffer<Eigen::Matrix3Xd>();
  J.setZero(3, impl_->model.nv);
  pinocchio::jacobianSubtreeCenterOfMass(impl_->model, impl_->data, q, id, J);
  pinocchio::centerOfMass(impl_->model, impl_->data, q, v, Eigen::VectorXd::Zero(impl_->model.nv));
  // A subtree's com[id] and acom[id] are in the frame of joint id
  // (center-of-mass.hxx's backward step); only com[0] is in the world.
  const pinocchio::SE3& oMi = impl_->data.oMi[id];
  return { oMi.act(impl_->data.com[id]), J, oMi.rotation() * impl_->data.acom[id] };
}

std::size_t PinocchioRobot::frameOf(const std::string& link) const
{
  if (!impl_->model.existBodyName(link))
    throw std::invalid_argument("PinocchioRobot::frameOf: no link " + link);
  return impl_->model.getBodyId(link);
}

const Matrix6Xd& PinocchioRobot::computeFrameJacobian(const Eigen::VectorXd& q, std::size_t frame, int reference)
{
  Matrix6Xd& J = buffer<Matrix6Xd>();
  if (J.cols() != impl_->model.nv)
    J.setZero(6, impl_->model.nv);
  pinocchio::computeFrameJacobian(impl_->model, impl_->data, q, frame, referenceFrame(reference), J);
  return J;
}

const Eigen::Matrix3Xd& PinocchioRobot::jacobianCenterOfMass(const Eigen::VectorXd& q)
{
  pinocchio::jacobianCenterOfMass(impl_->model, impl_->data, q, false);
  return impl_->data.Jcom;
}

}  // namespace drb_pinocchio
