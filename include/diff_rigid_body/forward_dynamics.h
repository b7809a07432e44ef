// Forward dynamics of a body and its derivatives (interface.md, Version 3):
//   x'' = M(x)^-1 (tau - c(x, x') - g(x))
// by the composite-rigid-body algorithm (crba.h), one Newton-Euler pass for
// c + g (rnea.h, x'' = 0) and M = L^T D L along the tree
// (tree_factorization.h). Differentiating M x'' + c + g = tau at x'' = FD:
//   dx''/dx   = -M^-1 dtau/dx,    dx''/dx' = -M^-1 dtau/dx',    dx''/dtau = M^-1,
// with dtau/dx, dtau/dx' of inverse dynamics at (x, x', x'')
// (rnea_derivatives.h). A singular M (a free root at gimbal lock, a
// coordinate that moves no mass) is reported, never inverted.
#pragma once

#include "diff_rigid_body/crba.h"
#include "diff_rigid_body/rnea.h"
#include "diff_rigid_body/rnea_derivatives.h"
#include "diff_rigid_body/tree_factorization.h"

namespace diff_rigid_body
{
/// x'' into `xdd` (d values) at (x, x', tau); null xd or tau means zeros.
/// Returns -1, or the coordinate at which M is singular (then `xdd` holds
/// no answer). Leaves M, its factorization and the kinematics in ws.
template <typename Scalar>
int forwardDynamics(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, const Scalar* xd,
                    const Scalar* tau, const Vector3<Scalar>& gravity, Scalar* xdd)
{
  crba(model, ws, x);
  inverseDynamicsFromKinematics(model, ws, xd, static_cast<const Scalar*>(nullptr), gravity, xdd,
                                /*inertias_ready=*/true);  // c + g
  const int singular = factorMassMatrix(model, ws);
  if (singular >= 0)
    return singular;
  for (std::size_t c = 0; c < model.coordinates; ++c)
    xdd[c] = (tau ? tau[c] : Scalar(0)) - xdd[c];
  solveMassMatrix(model, ws, xdd);
  return -1;
}

/// x'' (into `xdd`) and dx''/dx, dx''/dx', dx''/dtau = M^-1 (d x d each,
/// row = x'' component) at (x, x', tau). Returns as forwardDynamics.
template <typename Scalar>
int forwardDynamicsDerivatives(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, const Scalar* xd,
                               const Scalar* tau, const Vector3<Scalar>& gravity, Scalar* xdd,
                               typename BodyWorkspace<Scalar>::MatrixX& dxdd_dx,
                               typename BodyWorkspace<Scalar>::MatrixX& dxdd_dxd,
                               typename BodyWorkspace<Scalar>::MatrixX& inverse_mass)
{
  const int singular = forwardDynamics(model, ws, x, xd, tau, gravity, xdd);
  if (singular >= 0)
    return singular;
  // M's factorization stays in ws.factor; the derivatives of inverse dynamics
  // at x'' = FD recompute the kinematics but leave the factorization alone.
  inverseDynamicsDerivatives(model, ws, x, xd, xdd, gravity, dxdd_dx, dxdd_dxd);
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  inverse_mass.setIdentity(d, d);
  solveMassMatrixColumns(model, ws, inverse_mass);
  solveMassMatrixColumns(model, ws, dxdd_dx);
  solveMassMatrixColumns(model, ws, dxdd_dxd);
  dxdd_dx = -dxdd_dx;
  dxdd_dxd = -dxdd_dxd;
  return -1;
}

extern template int forwardDynamics<double>(const BodyModel&, BodyWorkspace<double>&, const double*, const double*,
                                            const double*, const Vector3<double>&, double*);
extern template int forwardDynamicsDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                                       const double*, const double*, const Vector3<double>&, double*,
                                                       Eigen::MatrixXd&, Eigen::MatrixXd&, Eigen::MatrixXd&);

}  // namespace diff_rigid_body
