// Errors of drb_bench_articulated's rows against 256-bit MPFR, from the same
// models and run as the times (written into the JSON's context as
// "articulated.<robot>.error.<quantity>.<method>"):
//
//   reference   our templated kernels evaluated in mpfr::mpreal (256 bits)
//               on the same model at the same double inputs: M (crba), tau
//               (inverseDynamics), x'' (forwardDynamics), M^-1 (its
//               factorization): exact for the double model to ~1e-77.
//   derivative references   central differences of those mpreal kernels
//               with h = 2^-100 (truncation ~h^2, rounding ~2^-156: both far
//               below double): dM/dx_j; dtau/dx, dtau/dx' (x'' fixed);
//               dx''/dx, dx''/dx' (tau fixed).
//   error       max over states of max|A - ref| / max|ref| over every entry
//               of the quantity (all j for dM/dx), the difference taken in
//               256 bits. Reported in units of eps = 2^-52 by the report.
//
// Peers in our coordinates (A^T M_peer A, A^T tau_peer; body_robots.h):
// KDL on a fixed base only, against the reference of the mass its chain
// covers (the segments off the chain massless); MuJoCo where the robot has
// no free joint (its free joint's coordinates are not ours); Pinocchio
// everywhere, as EulerZYX for the floating robot, with x'' and the ABA
// derivatives only where A is a permutation (no mimic joint: Pinocchio's
// mimic finger is an independent dof, so its constrained dynamics differ).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "body_robots.h"

namespace drb_bench
{
/// "<quantity>.<method>" -> max relative error over the states.
using ErrorTable = std::map<std::string, double>;

/// Keeps the largest error under `name` (a NaN sticks).
inline void recordMax(ErrorTable& table, const std::string& name, double error)
{
  auto it = table.find(name);
  if (it == table.end())
    table[name] = error;
  else if (!(error <= it->second))
    it->second = error;
}

/// Error states: 64 uniform as robotStates (seed 23), then every joint at
/// its lower limit and every joint at its upper limit (a free root at a
/// fixed pose away from gimbal lock).
inline std::vector<RobotState> errorStates(const Robot& robot)
{
  std::vector<RobotState> states = robotStates(robot, 66, 23);
  for (std::size_t i = 0; i < 2; ++i)
  {
    RobotState& s = states[64 + i];
    for (std::size_t b = 0; b < robot.bodies().size(); ++b)
    {
      const drb::BodyModel& body = robot.bodies()[b];
      double* x = s.x.data() + robot.offsets[b];
      const std::vector<double>& bound = i == 0 ? body.joint_lower : body.joint_upper;
      if (body.hasFreeRoot())
      {
        const double root[6] = { 0.3, -0.4, 0.5, 0.2, -0.1, 0.7 };
        std::copy(root, root + 6, x);
      }
      for (std::size_t k = 0; k < bound.size(); ++k)
        x[body.rootCoordinates() + k] = std::isfinite(bound[k]) ? bound[k] : 3.0;
    }
  }
  return states;
}

/// The largest 2-norm condition number of M over the error states,
/// lambda_max / lambda_min (body_errors.cpp): x'' = M^-1 (tau - c - g) and
/// M^-1 carry relative errors up to about that times eps, whatever the method.
double massMatrixConditioning(const Robot& robot);

/// M and dM/dx: ours, KDL, MuJoCo, Pinocchio (body_errors.cpp).
ErrorTable bodyErrors(const Robot& robot);
/// tau, dtau/dx and dtau/dx', x'', dx''/dx, dx''/dx' and M^-1 (dynamics_errors.cpp).
ErrorTable dynamicsErrors(const Robot& robot);

}  // namespace drb_bench
