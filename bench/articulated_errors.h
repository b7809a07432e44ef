// Errors of the articulated mass matrix and its derivatives, for
// drb_bench_articulated (reported in the JSON's context, so they come from
// the same run and the same models as the times).
//
//   reference   articulatedMassMatrix evaluated in 256-bit mpfr::mpreal on
//               the same model (articulated_kinematics.h is scalar-templated):
//               exact M of the double-precision model to ~1e-77.
//   error of A against B   max over states of max_ij |A_ij - B_ij| / max_ij |B_ij|
//               (difference taken in 256 bits for the reference).
//   dM/dx reference   central differences of the mpreal M with h = 2^-100
//               (truncation ~h^2, rounding ~2^-156: both far below double);
//               error max_j max|dM_j - ref_j| / max_j max|ref_j| per state.
// KDL's chain does not cover every segment (the Panda's right finger is not
// on panda_link0..panda_leftfinger), so KDL is compared with our M of the
// same model with the off-chain segments massless (massOnlyIn).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <mpreal.h>
#include <unsupported/Eigen/MPRealSupport>

#include "articulated_peers.h"
#include "diff_rigid_body/articulated_queries.h"

namespace drb_bench
{
using mpfr::mpreal;
using MatrixMp = Eigen::Matrix<mpreal, Eigen::Dynamic, Eigen::Dynamic>;

/// name -> max relative error over the states.
using ErrorTable = std::map<std::string, double>;

inline void recordMax(ErrorTable& table, const std::string& name, double error)
{
  auto it = table.find(name);
  if (it == table.end())
    table[name] = error;
  else if (!(error <= it->second))  // NaN sticks
    it->second = error;
}

inline MatrixMp referenceMassMatrix(const drb::ArticulatedBody& body, const std::vector<double>& x)
{
  std::vector<mpreal> xm(x.begin(), x.end());
  return drb::articulatedMassMatrix(body, xm.data());
}

/// max |A - ref| / max |ref|, in 256 bits.
inline double relativeError(const Eigen::MatrixXd& A, const MatrixMp& ref)
{
  mpreal diff = 0, scale = 0;
  for (Eigen::Index i = 0; i < ref.rows(); ++i)
    for (Eigen::Index j = 0; j < ref.cols(); ++j)
    {
      diff = std::max(diff, mpfr::abs(mpreal(A(i, j)) - ref(i, j)));
      scale = std::max(scale, mpfr::abs(ref(i, j)));
    }
  return (diff / scale).toDouble();
}

inline double relativeError(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B)
{
  return (A - B).cwiseAbs().maxCoeff() / B.cwiseAbs().maxCoeff();
}

/// Error states: 64 uniform within the limits, every joint at its lower
/// limit and every joint at its upper limit.
inline std::vector<std::vector<double>> errorStates(const drb::ArticulatedBody& body)
{
  std::vector<std::vector<double>> states = jointStates(body, 64, 23);
  for (const std::vector<double>* bound : { &body.joint_lower, &body.joint_upper })
  {
    std::vector<double> x(body.dofs(), 0.0);
    for (std::size_t k = 0; k < bound->size(); ++k)
      x[body.rootCoordinates() + k] = std::isfinite((*bound)[k]) ? (*bound)[k] : 3.0;
    states.push_back(x);
  }
  return states;
}

/// dM/dx error of articulatedMassMatrixDerivatives at x.
inline double derivativeError(const drb::ArticulatedBody& body, const std::vector<double>& x)
{
  const std::vector<Eigen::MatrixXd> ours = drb::articulatedMassMatrixDerivatives(body, x.data());
  const mpreal h = mpfr::pow(mpreal(2), -100);
  mpreal diff = 0, scale = 0;
  for (std::size_t j = 0; j < x.size(); ++j)
  {
    std::vector<mpreal> plus(x.begin(), x.end()), minus(x.begin(), x.end());
    plus[j] += h;
    minus[j] -= h;
    const MatrixMp ref = (drb::articulatedMassMatrix(body, plus.data()) - drb::articulatedMassMatrix(body, minus.data())) /
                         (2 * h);
    for (Eigen::Index r = 0; r < ref.rows(); ++r)
      for (Eigen::Index c = 0; c < ref.cols(); ++c)
      {
        diff = std::max(diff, mpfr::abs(mpreal(ours[j](r, c)) - ref(r, c)));
        scale = std::max(scale, mpfr::abs(ref(r, c)));
      }
  }
  return (diff / scale).toDouble();
}

/// Errors of `robot`'s M (ours, KDL, MuJoCo against the reference and
/// against each other) and of dM/dx, keyed "<quantity>.<a>_vs_<b>".
inline ErrorTable massMatrixErrors(const Robot& robot)
{
  const mp_prec_t previous = mpreal::get_default_prec();
  mpreal::set_default_prec(256);
  ErrorTable table;
  const drb::ArticulatedBody& body = *robot.body;
  const std::size_t dofs = body.dofs();
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  KdlArm kdl(robot);
  const drb::ArticulatedBody on_chain = massOnlyIn(body, kdl.links);
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  MujocoArm mujoco(robot);
#endif
  for (const std::vector<double>& x : errorStates(body))
  {
    const Eigen::MatrixXd ours = drb::articulatedMassMatrix(body, drb::articulatedPose(body, x.data()));
    const MatrixMp ref = referenceMassMatrix(body, x);
    recordMax(table, "M.ours_vs_reference", relativeError(ours, ref));
#ifdef DRB_BENCH_HAVE_MUJOCO
    mujoco.massMatrix(x.data());
    const Eigen::MatrixXd M_mj = mujoco.inCoordinates(dofs);
    recordMax(table, "M.mujoco_vs_reference", relativeError(M_mj, ref));
    recordMax(table, "M.ours_vs_mujoco", relativeError(ours, M_mj));
#endif
#ifdef DRB_BENCH_HAVE_KDL_PARSER
    const Eigen::MatrixXd ours_chain = drb::articulatedMassMatrix(on_chain, drb::articulatedPose(on_chain, x.data()));
    const MatrixMp ref_chain = referenceMassMatrix(on_chain, x);
    kdl.massMatrix(x.data());
    const Eigen::MatrixXd M_kdl = kdl.inCoordinates(dofs);
    recordMax(table, "M_chain.ours_vs_reference", relativeError(ours_chain, ref_chain));
    recordMax(table, "M_chain.kdl_vs_reference", relativeError(M_kdl, ref_chain));
    recordMax(table, "M_chain.ours_vs_kdl", relativeError(ours_chain, M_kdl));
#endif
  }
  const std::vector<std::vector<double>> states = errorStates(body);
  for (std::size_t i = 0; i < states.size(); i += 8)
    recordMax(table, "dM.ours_vs_reference", derivativeError(body, states[i]));
  mpreal::set_default_prec(previous);
  return table;
}

}  // namespace drb_bench
