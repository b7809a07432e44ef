// A 256-bit reference for forward dynamics near a free root's gimbal lock,
// by another route than the core's: M(x) (crba) and c + g (inverse dynamics
// at x'' = 0) in MPFR, then a dense LU solve of M x'' = tau - c - g in MPFR.
// The core never solves with M (forward_dynamics.h): it solves with H in
// motion coordinates and maps through the chart. cond(M) ~ 1 / cos^2(theta)
// is 1e24 at cos(theta) = 1e-12, which 256 bits (77 digits) absorb.
//
// Derivatives: central differences of that reference in MPFR with h = 2^-90
// (truncation h^2 ~ 1e-54, rounding 1e-77 cond(M) / h ~ 1e-26, relative).
//
// States: theta = +-(pi/2 - 10^-k) as doubles, k = 1..12, the other angles,
// rates and forces random (fixed seed); errors normwise relative,
// max|ours - ref| / max|ref|.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/LU>
#include <mpreal.h>
#include <unsupported/Eigen/MPRealSupport>

#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/rnea.h"

namespace drb_test
{
namespace gimbal
{
namespace drb = diff_rigid_body;
using Mp = mpfr::mpreal;
using VectorMp = Eigen::Matrix<Mp, Eigen::Dynamic, 1>;
using MatrixMp = Eigen::Matrix<Mp, Eigen::Dynamic, Eigen::Dynamic>;

/// One state at pitch sign (pi/2 - 10^-k).
struct State
{
  int k = 0;
  double sign = 1;
  Eigen::VectorXd x, xd, tau;
};

/// theta = +-(pi/2 - 10^-k), k = 1..12, both signs; the rest random in
/// [-1, 1] (angles [-pi, pi], forces [-3, 3]).
inline std::vector<State> gimbalStates(const drb::BodyModel& model, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  std::vector<State> states;
  for (int k = 1; k <= 12; ++k)
    for (const double sign : { 1.0, -1.0 })
    {
      State s{ k, sign, Eigen::VectorXd(d), Eigen::VectorXd(d), Eigen::VectorXd(d) };
      for (Eigen::Index i = 0; i < d; ++i)
      {
        s.x[i] = (i < 3 ? M_PI : 1.0) * unit(rng);
        s.xd[i] = unit(rng);
        s.tau[i] = 3.0 * unit(rng);
      }
      s.x[drb::THETA] = sign * (M_PI / 2 - std::pow(10.0, -k));
      states.push_back(s);
    }
  return states;
}

/// x'' = M^-1 (tau - c - g) in MPFR by the M route (see the header comment).
inline VectorMp referenceForwardDynamics(const drb::BodyModel& model, const VectorMp& x, const VectorMp& xd,
                                         const VectorMp& tau, const Eigen::Vector3d& gravity)
{
  drb::BodyWorkspace<Mp> ws(model);
  const Eigen::Index d = x.size();
  VectorMp bias(d);
  drb::inverseDynamics(model, ws, x.data(), xd.data(), static_cast<const Mp*>(nullptr),
                       drb::Vector3<Mp>(gravity.cast<Mp>()), bias.data());
  drb::crba(model, ws, x.data());
  return ws.M.partialPivLu().solve(VectorMp(tau - bias));
}

/// dx''/dx (by_rates false) or dx''/dx' (true) of the reference, column by
/// column from central differences in MPFR; only the `columns` listed (the
/// others left 0).
inline MatrixMp referenceDerivative(const drb::BodyModel& model, const Eigen::VectorXd& x, const Eigen::VectorXd& xd,
                                    const Eigen::VectorXd& tau, const Eigen::Vector3d& gravity, bool by_rates,
                                    const std::vector<Eigen::Index>& columns)
{
  const Eigen::Index d = x.size();
  const Mp h = mpfr::pow(Mp(2), -90);
  MatrixMp out = MatrixMp::Zero(d, d);
  const VectorMp tau_mp = tau.cast<Mp>();
  for (const Eigen::Index j : columns)
  {
    VectorMp xp = x.cast<Mp>(), xm = xp, vp = xd.cast<Mp>(), vm = vp;
    (by_rates ? vp : xp)[j] += h;
    (by_rates ? vm : xm)[j] -= h;
    out.col(j) = (referenceForwardDynamics(model, xp, vp, tau_mp, gravity) -
                  referenceForwardDynamics(model, xm, vm, tau_mp, gravity)) /
                 (2 * h);
  }
  return out;
}

/// max|a - ref| / max|ref| over the listed columns, in MPFR.
inline double relativeError(const Eigen::MatrixXd& a, const MatrixMp& ref, const std::vector<Eigen::Index>& columns)
{
  Mp diff = 0, scale = 0;
  for (const Eigen::Index j : columns)
    for (Eigen::Index i = 0; i < ref.rows(); ++i)
    {
      diff = std::max(diff, Mp(mpfr::abs(Mp(a(i, j)) - ref(i, j))));
      scale = std::max(scale, Mp(mpfr::abs(ref(i, j))));
    }
  return (diff / scale).toDouble();
}

}  // namespace gimbal
}  // namespace drb_test
