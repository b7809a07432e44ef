// Forward dynamics of a body and its derivatives (README, "Dynamics"):
//   x'' = M(x)^-1 (tau - c(x, x') - g(x))
// by the well-conditioned route (docs/derivation.md, "Conditioning near
// gimbal lock"): in motion coordinates nu (body_model.h), with H the mass
// matrix in nu (crba.h), b the bias of one Newton-Euler pass at nu' = 0
// (rnea.h) and H = L^T D L along the tree (tree_factorization.h),
//   nu' = H^-1 (A^-T tau - b),   x'' = A^-1 (nu' - Q)
// (motion_coordinates.h). M = A^T H A is never formed or solved: its
// condition grows like 1 / cos^2(theta), H's does not, and only A^-1 = T^-1
// carries 1 / cos(theta), once.
//
// Derivatives, with D_q, D_nu those of inverse dynamics in nu at
// (nu, nu') (rnea_derivatives.h, from the same kinematics and composite
// inertias) and dA_c = dA/dx_c; H^-1 once from the factorization (d tree
// solves), then two products with it:
//   dnu'/dx_c = -H^-1 (D_q A e_c + D_nu dA_c x' + A^-T dA_c^T A^-T tau)
//   dx''/dx_c = A^-1 (dnu'/dx_c - dQ/dx_c - dA_c x'')
//   dx''/dx'  = A^-1 (-H^-1 D_nu A - dQ/dx')
//   dx''/dtau = A^-1 H^-1 A^-T = M^-1.
// Refused: a free root whose |cos(theta)| is below kGimbalLockCosine (the
// chart itself is singular), and a singular H (a coordinate that moves no
// mass).
#pragma once

#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/rnea.h"
#include "diff_rigid_body/algorithm/rnea_derivatives.h"
#include "diff_rigid_body/algorithm/tree_factorization.h"

namespace diff_rigid_body
{
namespace detail
{
/// Whether a free root's chart is singular at the kinematics in ws.
template <typename Scalar>
bool chartIsSingular(const BodyModel& model, const BodyWorkspace<Scalar>& ws)
{
  return model.hasFreeRoot() && !(pivotMagnitude(ws.chart.c_theta) >= kGimbalLockCosine);
}

/// T^-T in the free root's rotation rows of `m` (tau_nu = A^-T tau).
template <typename Scalar, typename Matrix>
void rotationRowsToMotion(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Matrix& m)
{
  if (model.hasFreeRoot())
    mapRotationRows(model, Matrix3<Scalar>(ws.chart.inverse().transpose()), m);
}

/// x'' = A^-1 (nu' - Q) in place, nu' given at `xdd`.
template <typename Scalar>
void accelerationsToCoordinates(const BodyModel& model, const BodyWorkspace<Scalar>& ws, const Scalar* xd,
                                Scalar* xdd)
{
  if (!model.hasFreeRoot())
    return;
  Eigen::Map<Vector3<Scalar>> rotation(xdd);
  if (xd)
    rotation -= ws.chart.velocityProduct(xd);
  rotation = (ws.chart.inverse() * rotation).eval();
}
}  // namespace detail

/// x'' into `xdd` (d values) at (x, x', tau); null xd or tau means zeros.
/// Returns -1, or the coordinate at which the problem is singular (THETA
/// for a free root at gimbal lock; then `xdd` holds no answer). Leaves the
/// kinematics, H and its factorization, nu (motionRates), nu' (in ws.nu_dot
/// for a free root) and A^-T tau (ws.force_nu) in ws.
template <typename Scalar>
int forwardDynamics(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, const Scalar* xd,
                    const Scalar* tau, const Vector3<Scalar>& gravity, Scalar* xdd)
{
  forwardKinematics(model, ws, x);
  if (detail::chartIsSingular(model, ws))
    return THETA;
  crbaFromKinematics(model, ws);
  const Scalar* nu = motionRates(model, ws, xd);
  inverseDynamicsInMotion(model, ws, nu, static_cast<const Scalar*>(nullptr), gravity, xdd,
                          /*inertias_ready=*/true);  // b
  const int singular = factorMassMatrix(model, ws);
  if (singular >= 0)
    return singular;
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  if (tau)
    ws.force_nu = Eigen::Map<const typename BodyWorkspace<Scalar>::VectorX>(tau, d);
  else
    ws.force_nu.setZero();
  detail::rotationRowsToMotion(model, ws, ws.force_nu);
  for (Eigen::Index c = 0; c < d; ++c)
    xdd[c] = ws.force_nu[c] - xdd[c];
  solveMassMatrix(model, ws, xdd);  // nu'
  if (model.hasFreeRoot())
    ws.nu_dot = Eigen::Map<const typename BodyWorkspace<Scalar>::VectorX>(xdd, d);
  detail::accelerationsToCoordinates(model, ws, xd, xdd);
  return -1;
}

namespace detail
{
/// B = D_q A + D_nu dA x' + A^-T dA^T A^-T tau and D_nu A in place of D_q
/// (by_x) and D_nu (by_xd), before the solve with H (see the header comment).
template <typename Scalar>
void forwardDerivativesBeforeSolve(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* xd,
                                   typename BodyWorkspace<Scalar>::MatrixX& by_x,
                                   typename BodyWorkspace<Scalar>::MatrixX& by_xd)
{
  const FreeRootChart<Scalar>& chart = ws.chart;
  const Vector3<Scalar> rates = xd ? Vector3<Scalar>(Eigen::Map<const Vector3<Scalar>>(xd)) : Vector3<Scalar>::Zero();
  const Matrix3<Scalar> inverse_transpose = chart.inverse().transpose();
  const Vector3<Scalar> moment = ws.force_nu.template head<3>();
  for (int c = THETA; c <= PSI; ++c)
    ws.chart_columns.col(c - THETA).noalias() = by_xd.template leftCols<3>() * (chart.derivative(c) * rates);
  columnsToCoordinates(model, ws, by_x);
  columnsToCoordinates(model, ws, by_xd);
  for (int c = THETA; c <= PSI; ++c)
  {
    by_x.col(c) += ws.chart_columns.col(c - THETA);
    by_x.col(c).template head<3>() += inverse_transpose * (chart.derivative(c).transpose() * moment);
  }
}

/// dx''/dx and dx''/dx' from -H^-1 B and -H^-1 D_nu A in place (see the
/// header comment); xdd holds x''.
template <typename Scalar>
void forwardDerivativesAfterSolve(const BodyModel& model, const BodyWorkspace<Scalar>& ws, const Scalar* xd,
                                  const Scalar* xdd, typename BodyWorkspace<Scalar>::MatrixX& by_x,
                                  typename BodyWorkspace<Scalar>::MatrixX& by_xd)
{
  const FreeRootChart<Scalar>& chart = ws.chart;
  const Vector3<Scalar> rates = xd ? Vector3<Scalar>(Eigen::Map<const Vector3<Scalar>>(xd)) : Vector3<Scalar>::Zero();
  const Vector3<Scalar> accelerations = Eigen::Map<const Vector3<Scalar>>(xdd);
  const Matrix3<Scalar> dQ_dangles = chart.velocityProductByAngles(rates.data());
  for (int c = THETA; c <= PSI; ++c)
    by_x.col(c).template head<3>() -= dQ_dangles.col(c) + chart.derivative(c) * accelerations;
  by_xd.template topLeftCorner<3, 3>() -= chart.velocityProductByRates(rates.data());
  const Matrix3<Scalar> inverse = chart.inverse();
  mapRotationRows(model, inverse, by_x);
  mapRotationRows(model, inverse, by_xd);
}
}  // namespace detail

/// M^-1 = A^-1 H^-1 A^-T into `inverse_mass` (d x d) from the kinematics
/// and H's factorization in ws (forwardDynamics first); H^-1 stays in
/// ws.inverse_h.
template <typename Scalar>
void inverseMassMatrix(const BodyModel& model, BodyWorkspace<Scalar>& ws,
                       typename BodyWorkspace<Scalar>::MatrixX& inverse_mass)
{
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  ws.inverse_h.setIdentity(d, d);
  solveMassMatrixColumns(model, ws, ws.inverse_h);
  inverse_mass = ws.inverse_h;
  if (!model.hasFreeRoot())
    return;
  const Matrix3<Scalar> inverse = ws.chart.inverse();
  mapRotationRows(model, inverse, inverse_mass);
  mapRotationColumns(model, Matrix3<Scalar>(inverse.transpose()), inverse_mass);
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
  // The kinematics, composite inertias, H's factorization, nu and nu' stay
  // in ws: the derivatives of inverse dynamics in nu at nu' = FD reuse them.
  const Scalar* nu = motionRates(model, ws, xd);
  const Scalar* nu_dot = model.hasFreeRoot() ? ws.nu_dot.data() : xdd;
  inverseDynamicsDerivativesInMotion(model, ws, nu, nu_dot, gravity, dxdd_dx, dxdd_dxd);
  if (model.hasFreeRoot())
    detail::forwardDerivativesBeforeSolve(model, ws, xd, dxdd_dx, dxdd_dxd);
  inverseMassMatrix(model, ws, inverse_mass);  // H^-1 once, then two products
  ws.product.noalias() = -ws.inverse_h * dxdd_dx;
  dxdd_dx.swap(ws.product);
  ws.product.noalias() = -ws.inverse_h * dxdd_dxd;
  dxdd_dxd.swap(ws.product);
  if (model.hasFreeRoot())
    detail::forwardDerivativesAfterSolve(model, ws, xd, xdd, dxdd_dx, dxdd_dxd);
  return -1;
}

extern template int forwardDynamics<double>(const BodyModel&, BodyWorkspace<double>&, const double*, const double*,
                                            const double*, const Vector3<double>&, double*);
extern template int forwardDynamicsDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                                       const double*, const double*, const Vector3<double>&, double*,
                                                       Eigen::MatrixXd&, Eigen::MatrixXd&, Eigen::MatrixXd&);

}  // namespace diff_rigid_body
