// Our algorithms over a whole robot (body_robots.h), for the error
// measurements of drb_bench_articulated: every body at its slice of x, the
// results assembled in the robot's coordinates (a block per body: the
// bodies of a robot share no coordinate, so M, dtau/dx, ... are block
// diagonal). Templated on the scalar like the kernels (double for ours,
// mpfr::mpreal for the reference). Allocates freely: not for timing.
#pragma once

#include <stdexcept>
#include <vector>

#include "body_robots.h"
#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "diff_rigid_body/algorithm/mass_matrix_derivatives.h"
#include "diff_rigid_body/algorithm/rnea.h"
#include "diff_rigid_body/algorithm/rnea_derivatives.h"

namespace drb_bench
{
template <typename Scalar>
using MatrixX = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
template <typename Scalar>
using VectorX = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

/// The bodies of a robot (or a copy with other masses) and where their x starts.
struct RobotModel
{
  const std::vector<drb::BodyModel>& bodies;
  const std::vector<std::size_t>& offsets;
  std::size_t coordinates;
};

inline RobotModel modelOf(const Robot& robot)
{
  return { robot.bodies(), robot.offsets, robot.coordinates };
}

template <typename Scalar>
std::vector<Scalar> toScalar(const std::vector<double>& values)
{
  return std::vector<Scalar>(values.begin(), values.end());
}

/// M(x), d x d.
template <typename Scalar>
MatrixX<Scalar> robotMassMatrix(const RobotModel& robot, const std::vector<Scalar>& x)
{
  MatrixX<Scalar> M = MatrixX<Scalar>::Zero(robot.coordinates, robot.coordinates);
  for (std::size_t b = 0; b < robot.bodies.size(); ++b)
  {
    const drb::BodyModel& body = robot.bodies[b];
    drb::BodyWorkspace<Scalar> ws(body);
    drb::crba(body, ws, x.data() + robot.offsets[b]);
    M.block(robot.offsets[b], robot.offsets[b], body.coordinates, body.coordinates) = ws.M;
  }
  return M;
}

/// dM/dx_j for j < d, d x d each (ours: massMatrixDerivatives).
inline std::vector<Eigen::MatrixXd> robotMassMatrixDerivatives(const RobotModel& robot, const std::vector<double>& x)
{
  const Eigen::Index d = static_cast<Eigen::Index>(robot.coordinates);
  std::vector<Eigen::MatrixXd> dM(robot.coordinates, Eigen::MatrixXd::Zero(d, d));
  for (std::size_t b = 0; b < robot.bodies.size(); ++b)
  {
    const drb::BodyModel& body = robot.bodies[b];
    const std::size_t n = body.coordinates, o = robot.offsets[b];
    drb::BodyWorkspace<double> ws(body);
    std::vector<double> values(n * n * n);
    drb::massMatrixDerivatives(body, ws, x.data() + o, values.data());
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t r = 0; r < n; ++r)
        for (std::size_t c = 0; c < n; ++c)
          dM[o + j](o + r, o + c) = values[j * n * n + r * n + c];
  }
  return dM;
}

/// tau(x, x', x'') with gravity gamma [m/s^2].
template <typename Scalar>
VectorX<Scalar> robotInverseDynamics(const RobotModel& robot, const std::vector<Scalar>& x,
                                     const std::vector<Scalar>& xd, const std::vector<Scalar>& xdd,
                                     const Eigen::Vector3d& gravity)
{
  VectorX<Scalar> tau(robot.coordinates);
  for (std::size_t b = 0; b < robot.bodies.size(); ++b)
  {
    const std::size_t o = robot.offsets[b];
    drb::BodyWorkspace<Scalar> ws(robot.bodies[b]);
    drb::inverseDynamics(robot.bodies[b], ws, x.data() + o, xd.data() + o, xdd.data() + o,
                         drb::Vector3<Scalar>(gravity.cast<Scalar>()), tau.data() + o);
  }
  return tau;
}

/// x''(x, x', tau); throws where M is singular.
template <typename Scalar>
VectorX<Scalar> robotForwardDynamics(const RobotModel& robot, const std::vector<Scalar>& x,
                                     const std::vector<Scalar>& xd, const std::vector<Scalar>& tau,
                                     const Eigen::Vector3d& gravity)
{
  VectorX<Scalar> xdd(robot.coordinates);
  for (std::size_t b = 0; b < robot.bodies.size(); ++b)
  {
    const std::size_t o = robot.offsets[b];
    drb::BodyWorkspace<Scalar> ws(robot.bodies[b]);
    if (drb::forwardDynamics(robot.bodies[b], ws, x.data() + o, xd.data() + o, tau.data() + o,
                             drb::Vector3<Scalar>(gravity.cast<Scalar>()), xdd.data() + o) >= 0)
      throw std::runtime_error("forward dynamics: M is singular");
  }
  return xdd;
}

/// M(x)^-1 = A^-1 H^-1 A^-T from our factorization of H (forward_dynamics.h).
template <typename Scalar>
MatrixX<Scalar> robotInverseMass(const RobotModel& robot, const std::vector<Scalar>& x)
{
  MatrixX<Scalar> inverse = MatrixX<Scalar>::Zero(robot.coordinates, robot.coordinates);
  for (std::size_t b = 0; b < robot.bodies.size(); ++b)
  {
    const drb::BodyModel& body = robot.bodies[b];
    const Eigen::Index n = static_cast<Eigen::Index>(body.coordinates), o = static_cast<Eigen::Index>(robot.offsets[b]);
    drb::BodyWorkspace<Scalar> ws(body);
    std::vector<Scalar> xdd(static_cast<std::size_t>(n));
    if (drb::forwardDynamics(body, ws, x.data() + o, static_cast<const Scalar*>(nullptr),
                             static_cast<const Scalar*>(nullptr), drb::Vector3<Scalar>::Zero().eval(), xdd.data()) >= 0)
      throw std::runtime_error("inverse mass: M is singular");
    MatrixX<Scalar> block(n, n);
    drb::inverseMassMatrix(body, ws, block);
    inverse.block(o, o, n, n) = block;
  }
  return inverse;
}

/// A pair of d x d matrices: by x and by x' (or dx''/dx, dx''/dx'), and M^-1 for FD.
struct Derivatives
{
  Eigen::MatrixXd by_x, by_xd, inverse_mass;
};

/// Ours: dtau/dx, dtau/dx' (inverseDynamicsDerivatives).
inline Derivatives robotInverseDynamicsDerivatives(const RobotModel& robot, const RobotState& s,
                                                   const Eigen::Vector3d& gravity)
{
  const Eigen::Index d = static_cast<Eigen::Index>(robot.coordinates);
  Derivatives out{ Eigen::MatrixXd::Zero(d, d), Eigen::MatrixXd::Zero(d, d), {} };
  for (std::size_t b = 0; b < robot.bodies.size(); ++b)
  {
    const drb::BodyModel& body = robot.bodies[b];
    const Eigen::Index n = static_cast<Eigen::Index>(body.coordinates), o = static_cast<Eigen::Index>(robot.offsets[b]);
    drb::BodyWorkspace<double> ws(body);
    Eigen::MatrixXd dx(n, n), dxd(n, n);
    drb::inverseDynamicsDerivatives(body, ws, s.x.data() + o, s.xd.data() + o, s.xdd.data() + o, gravity, dx, dxd);
    out.by_x.block(o, o, n, n) = dx;
    out.by_xd.block(o, o, n, n) = dxd;
  }
  return out;
}

/// Ours: dx''/dx, dx''/dx', M^-1 (forwardDynamicsDerivatives) at (x, x', tau).
inline Derivatives robotForwardDynamicsDerivatives(const RobotModel& robot, const RobotState& s,
                                                   const Eigen::Vector3d& gravity)
{
  const Eigen::Index d = static_cast<Eigen::Index>(robot.coordinates);
  Derivatives out{ Eigen::MatrixXd::Zero(d, d), Eigen::MatrixXd::Zero(d, d), Eigen::MatrixXd::Zero(d, d) };
  for (std::size_t b = 0; b < robot.bodies.size(); ++b)
  {
    const drb::BodyModel& body = robot.bodies[b];
    const Eigen::Index n = static_cast<Eigen::Index>(body.coordinates), o = static_cast<Eigen::Index>(robot.offsets[b]);
    drb::BodyWorkspace<double> ws(body);
    Eigen::MatrixXd dx(n, n), dxd(n, n), inverse(n, n);
    std::vector<double> xdd(static_cast<std::size_t>(n));
    if (drb::forwardDynamicsDerivatives(body, ws, s.x.data() + o, s.xd.data() + o, s.tau.data() + o, gravity,
                                        xdd.data(), dx, dxd, inverse) >= 0)
      throw std::runtime_error("forward dynamics derivatives: M is singular");
    out.by_x.block(o, o, n, n) = dx;
    out.by_xd.block(o, o, n, n) = dxd;
    out.inverse_mass.block(o, o, n, n) = inverse;
  }
  return out;
}

}  // namespace drb_bench
