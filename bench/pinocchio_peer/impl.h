// Private to drb_pinocchio_peer: PinocchioRobot::Impl, shared by the
// translation units of bench/pinocchio_peer/ (one algorithm each).
#pragma once

#include <string>
#include <vector>

#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>

#include "pinocchio_peer.h"

namespace drb_pinocchio
{

struct PinocchioRobot::Impl
{
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW

  Impl(pinocchio::Model m, PinocchioRoot r) : model(std::move(m)), data(model), root(r) {}

  pinocchio::Model model;
  pinocchio::Data data;  ///< allocated once, after the model is complete
  PinocchioRoot root;
  std::vector<JointInfo> joints;
  std::vector<FloatingBody> floating;
};

/// Copies the strictly upper triangle of a square matrix to its strictly lower one.
template <typename Matrix>
inline void fillLowerTriangle(Matrix& m)
{
  m.template triangularView<Eigen::StrictlyLower>() = m.transpose().template triangularView<Eigen::StrictlyLower>();
}

}  // namespace drb_pinocchio
