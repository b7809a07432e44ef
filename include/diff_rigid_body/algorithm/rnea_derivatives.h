// Analytic derivatives of inverse dynamics (rnea.h), dtau/dx and dtau/dx',
// in the fixed frame about r (after Carpentier and Mansard, "Analytical
// derivatives of rigid body dynamics algorithms", RSS 2018; derived anew for
// these coordinates in docs/derivation.md, "Derivatives of inverse dynamics").
//
// In motion coordinates (body_model.h): moving dof j (along S_j, at fixed nu
// and nu') carries the segments it moves and the dofs below its block:
// their unit motions, inertias and Newton-Euler forces
// f_s = Y_s a_s + v_s x* Y_s v_s change as if carried by S_j, except that
// their velocity and acceleration also lose what dof j's block put there:
//   df_s/dq_j  = S_j x* f_s - Y_s w_j - B_s u_j,
//   df_s/dq'_j = B_s S_j - Y_s ubar_j,
// with l = the last dof of j's block (j itself for a 1-dof joint),
// u_j = S_j x v_l, w_j = S_j x a_l - u_j x v_l (v_l, a_l: the motion of what
// dof l moves, gravity included in a_l), ubar_j = u_j - v_carrier x S_j
// (= 2 u_j for a 1-dof joint), and B_s the linear map
//   B_s m = Y_s (m x v_s) + m x* (Y_s v_s) + v_s x* (Y_s m)
//         = (T_s m.w, -2 p_s x m.w),
//   T_s = [w]I - I[w] - [v][h] - [h][v] - [I w + h x v],  p_s = m v + w x h,
// for v_s = (w, v) and Y_s = (m, h, I): B_s reads only the angular part of
// its argument. Summed over subtrees (Ic, F, T^c, p^c) and paired with the
// unit motions (tau_i = S_i . F_seg(i)), for dofs i, j:
//   j an ancestor of i, or i:   dtau_i/dq_j  = -F^M_i . w_j - G_i . u_j.w
//     (S_i carried by j)        dtau_i/dq'_j =  G_i . S_j.w - F^M_i . ubar_j
//   i strictly above j, or in   dtau_i/dq_j  =  S_i . (S_j x* F_j - Ic_j w_j - B^c_j u_j)
//     j's block after j:        (and dtau_i/dq'_j as the first line for the block)
//   i strictly above j:         dtau_i/dq'_j =  S_i . (B^c_j S_j - Ic_j ubar_j)
// where F^M_i = Ic_i S_i (the CRBA's momentum) and G_i = T^c_i^T S_i.w -
// 2 S_i.v x p^c_i (the angular part of B^c_i^T S_i); every other pair is 0.
// In nu: d/dq along nu_c sums m_j d/dq_j over the dofs j that nu_c drives,
// and tau[c_i] carries m_i. Work: O(dofs x depth), no 6 x 6 matrix.
//
// In x (motion_coordinates.h), with tau = A^T tau_nu(nu = A x', nu' = A x'' + Q):
//   dtau/dx_c  = A^T [D_q A e_c + D_nu dA_c x' + H (dA_c x'' + dQ/dx_c)] + dA_c^T tau_nu
//   dtau/dx'   = A^T [D_nu A + H dQ/dx']
// (D_q, D_nu the derivatives in nu above, dA_c = dA/dx_c; only a free root's
// theta and psi columns carry the dA and dQ terms). dtau/dx' = 2 C, the
// Christoffel Coriolis matrix of the equations of motion (README, "Dynamics").
#pragma once

#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/rnea.h"

namespace diff_rigid_body
{
namespace detail
{
/// Skew matrix [a]x.
template <typename Scalar>
Matrix3<Scalar> skew(const Vector3<Scalar>& a)
{
  Matrix3<Scalar> S;
  S << Scalar(0), -a[2], a[1], a[2], Scalar(0), -a[0], -a[1], a[0], Scalar(0);
  return S;
}

/// T_s and p_s of every segment (see the header), then summed over subtrees
/// into ws.composite_velocity_rate: its top-left 3 x 3 block holds T^c, its
/// column 3 (rows 0..2) p^c.
template <typename Scalar>
void velocityRates(const BodyModel& model, BodyWorkspace<Scalar>& ws)
{
  for (std::size_t s = 0; s < model.segments.size(); ++s)
  {
    const Segment& segment = model.segments[s];
    const Motion<Scalar>& v = ws.dof_velocity[static_cast<std::size_t>(segment.first_dof + segment.dof_count - 1)];
    const Inertia<Scalar>& Y = ws.body_inertia[s];
    const Matrix3<Scalar> W = skew(v.w), V = skew(v.v), H = skew(Y.h);
    const Vector3<Scalar> hn = Y.I * v.w + spatial::cross(Y.h, v.v);
    typename BodyWorkspace<Scalar>::Matrix6& rate = ws.composite_velocity_rate[s];
    rate.template topLeftCorner<3, 3>() = W * Y.I - Y.I * W - V * H - H * V - skew(hn);
    rate.template block<3, 1>(0, 3) = Y.m * v.v + spatial::cross(v.w, Y.h);
  }
  for (std::size_t s = model.segments.size(); s-- > 1;)
  {
    const std::size_t parent = static_cast<std::size_t>(model.segments[s].parent);
    ws.composite_velocity_rate[parent].template topLeftCorner<3, 4>() +=
        ws.composite_velocity_rate[s].template topLeftCorner<3, 4>();
  }
}

/// B^c m = (T^c m.w, -2 p^c x m.w) of segment s's subtree.
template <typename Scalar>
Force<Scalar> applyVelocityRate(const BodyWorkspace<Scalar>& ws, std::size_t s, const Vector3<Scalar>& angular)
{
  const auto& rate = ws.composite_velocity_rate[s];
  Force<Scalar> out;
  out.n = rate.template topLeftCorner<3, 3>() * angular;
  out.f = Scalar(-2) * spatial::cross(Vector3<Scalar>(rate.template block<3, 1>(0, 3)), angular);
  return out;
}

/// Per dof k: u_k, w_k, G_k, and what moving it adds above it (by q in
/// `moved`, by q' returned through `moved_rate`).
template <typename Scalar>
void dofDerivativeTerms(const BodyModel& model, BodyWorkspace<Scalar>& ws, std::vector<Force<Scalar>>& moved_rate)
{
  for (std::size_t k = 0; k < model.dofs.size(); ++k)
  {
    const Dof& dof = model.dofs[k];
    const std::size_t s = static_cast<std::size_t>(dof.segment);
    const std::size_t last = static_cast<std::size_t>(dof.block_last);
    const Motion<Scalar>& S = ws.S[k];
    auto& terms = ws.dof_terms[k];
    terms.u = spatial::crossMotion(S, ws.dof_velocity[last]);
    if (dof.block_last == static_cast<int>(k) && dof.carrier == dof.parent)  // 1-dof: v_carrier x S_k = -u_k
    {
      terms.ubar.w = Scalar(2) * terms.u.w;
      terms.ubar.v = Scalar(2) * terms.u.v;
    }
    else
    {
      const Motion<Scalar> beta = dof.carrier < 0 ? Motion<Scalar>() : spatial::crossMotion(ws.dof_velocity[static_cast<std::size_t>(dof.carrier)], S);
      terms.ubar.w = terms.u.w - beta.w;
      terms.ubar.v = terms.u.v - beta.v;
    }
    const Motion<Scalar> Sa = spatial::crossMotion(S, ws.dof_acceleration[last]);
    const Motion<Scalar> uv = spatial::crossMotion(terms.u, ws.dof_velocity[last]);
    terms.w.w = Sa.w - uv.w;
    terms.w.v = Sa.v - uv.v;
    const auto& rate = ws.composite_velocity_rate[s];
    terms.gamma.n = rate.template topLeftCorner<3, 3>().transpose() * S.w -
                    Scalar(2) * spatial::cross(S.v, Vector3<Scalar>(rate.template block<3, 1>(0, 3)));
    const Force<Scalar> carried = spatial::crossForce(S, ws.subtree_force[s]);
    const Force<Scalar> Iw = spatial::momentum(ws.composite[s], terms.w);
    const Force<Scalar> Bu = applyVelocityRate(ws, s, terms.u.w);
    terms.moved.n = carried.n - Iw.n - Bu.n;
    terms.moved.f = carried.f - Iw.f - Bu.f;
    const Force<Scalar> BS = applyVelocityRate(ws, s, S.w);
    const Force<Scalar> Iu = spatial::momentum(ws.composite[s], terms.ubar);
    moved_rate[k].n = BS.n - Iu.n;
    moved_rate[k].f = BS.f - Iu.f;
  }
}
}  // namespace detail

/// dtau_nu/dq and dtau_nu/dnu (d x d, column-major Eigen matrices of ws's
/// scalar: row = tau_nu component, column = direction in nu) at nu, nu'
/// (null: zeros), from the kinematics and composite inertias in ws; tau_nu
/// into ws.tau.
template <typename Scalar>
void inverseDynamicsDerivativesInMotion(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* nu,
                                        const Scalar* nu_dot, const Vector3<Scalar>& gravity,
                                        typename BodyWorkspace<Scalar>::MatrixX& dtau_dq,
                                        typename BodyWorkspace<Scalar>::MatrixX& dtau_dnu)
{
  inverseDynamicsInMotion(model, ws, nu, nu_dot, gravity, ws.tau.data(), /*inertias_ready=*/true);
  detail::velocityRates(model, ws);
  std::vector<Force<Scalar>>& moved_rate = ws.momentum_rate;
  detail::dofDerivativeTerms(model, ws, moved_rate);
  dtau_dq.setZero();
  dtau_dnu.setZero();
  for (std::size_t i = 0; i < model.dofs.size(); ++i)
  {
    const Dof& dof_i = model.dofs[i];
    const std::size_t seg_i = static_cast<std::size_t>(dof_i.segment);
    const Force<Scalar> FM = spatial::momentum(ws.composite[seg_i], ws.S[i]);
    const auto& terms_i = ws.dof_terms[i];
    for (int j = static_cast<int>(i); j >= 0; j = model.dofs[static_cast<std::size_t>(j)].parent)
    {
      // j an ancestor of i, or i.
      const Dof& dof_j = model.dofs[static_cast<std::size_t>(j)];
      const auto& terms_j = ws.dof_terms[static_cast<std::size_t>(j)];
      const Scalar m(dof_i.multiplier * dof_j.multiplier);
      if (j != static_cast<int>(i) && dof_j.block_last >= static_cast<int>(i))  // i in j's block: not carried
        dtau_dq(dof_i.coordinate, dof_j.coordinate) += m * spatial::power(ws.S[i], terms_j.moved);
      else
        dtau_dq(dof_i.coordinate, dof_j.coordinate) -=
            m * (spatial::power(terms_j.w, FM) + spatial::dot(terms_i.gamma.n, terms_j.u.w));
      dtau_dnu(dof_i.coordinate, dof_j.coordinate) +=
          m * (spatial::dot(terms_i.gamma.n, ws.S[static_cast<std::size_t>(j)].w) - spatial::power(terms_j.ubar, FM));
      if (j == static_cast<int>(i))
        continue;
      // i below j: row j, column i.
      dtau_dq(dof_j.coordinate, dof_i.coordinate) +=
          m * spatial::power(ws.S[static_cast<std::size_t>(j)], terms_i.moved);
      dtau_dnu(dof_j.coordinate, dof_i.coordinate) +=
          m * spatial::power(ws.S[static_cast<std::size_t>(j)], moved_rate[i]);
    }
  }
}

namespace detail
{
/// The derivatives in nu (dtau_dx = D_q, dtau_dxd = D_nu) turned into x, in
/// place, for a free root (see the header comment); ws.tau holds tau_nu and
/// the composite inertias are in ws.
template <typename Scalar>
void inverseDynamicsDerivativesToCoordinates(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* xd,
                                             const Scalar* xdd, typename BodyWorkspace<Scalar>::MatrixX& dtau_dx,
                                             typename BodyWorkspace<Scalar>::MatrixX& dtau_dxd)
{
  const FreeRootChart<Scalar>& chart = ws.chart;
  const Vector3<Scalar> rates = xd ? Vector3<Scalar>(Eigen::Map<const Vector3<Scalar>>(xd)) : Vector3<Scalar>::Zero();
  const Vector3<Scalar> accelerations =
      xdd ? Vector3<Scalar>(Eigen::Map<const Vector3<Scalar>>(xdd)) : Vector3<Scalar>::Zero();
  rotationColumnsOfH(model, ws);
  const auto& H_w = ws.rotation_columns;
  const Matrix3<Scalar> dQ_dangles = chart.velocityProductByAngles(rates.data());
  auto& chart_terms = ws.chart_columns;  // column c - THETA: the dA_c and dQ/dx_c terms
  for (int c = THETA; c <= PSI; ++c)
  {
    const Matrix3<Scalar> dT = chart.derivative(c);
    const Vector3<Scalar> by_rates = dT * rates, by_accelerations = dT * accelerations + dQ_dangles.col(c);
    chart_terms.col(c - THETA).noalias() = dtau_dxd.template leftCols<3>() * by_rates;
    chart_terms.col(c - THETA).noalias() += H_w * by_accelerations;
  }
  const Matrix3<Scalar> dQ_drates = chart.velocityProductByRates(rates.data());
  columnsToCoordinates(model, ws, dtau_dx);
  for (int c = THETA; c <= PSI; ++c)
    dtau_dx.col(c) += chart_terms.col(c - THETA);
  columnsToCoordinates(model, ws, dtau_dxd);
  dtau_dxd.template leftCols<3>().noalias() += H_w * dQ_drates;
  rowsToCoordinates(model, ws, dtau_dx);
  rowsToCoordinates(model, ws, dtau_dxd);
  const Vector3<Scalar> moment = ws.tau.template head<3>();
  for (int c = THETA; c <= PSI; ++c)
    dtau_dx.col(c).template head<3>() += chart.derivative(c).transpose() * moment;
}
}  // namespace detail

/// dtau/dx and dtau/dx' (d x d, column-major Eigen matrices of ws's scalar:
/// row = tau component, column = coordinate) at (x, x', x'') (null: zeros).
/// Also leaves the kinematics, composite inertias, momenta and tau_nu in ws.
template <typename Scalar>
void inverseDynamicsDerivatives(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, const Scalar* xd,
                                const Scalar* xdd, const Vector3<Scalar>& gravity,
                                typename BodyWorkspace<Scalar>::MatrixX& dtau_dx,
                                typename BodyWorkspace<Scalar>::MatrixX& dtau_dxd)
{
  forwardKinematics(model, ws, x);
  detail::compositeInertias(model, ws);
  const Scalar* nu_dot = motionAccelerations(model, ws, xd, xdd);
  inverseDynamicsDerivativesInMotion(model, ws, motionRates(model, ws, xd), nu_dot, gravity, dtau_dx, dtau_dxd);
  if (model.hasFreeRoot())
    detail::inverseDynamicsDerivativesToCoordinates(model, ws, xd, xdd, dtau_dx, dtau_dxd);
}

/// The node's inverse dynamics at (x, x', x'') from one kinematics: tau,
/// the velocity terms c = tau(x, x', 0) with gamma = 0 and the gravity
/// terms g = tau(x, 0, 0) (d values each), and, when `dtau_dx` is not null,
/// dtau/dx and dtau/dx' (into dtau_dx, dtau_dxd). tau and its derivatives
/// come from one Newton-Euler pass, c from a second (velocities only), g
/// from the composite inertias.
template <typename Scalar>
void inverseDynamicsTerms(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, const Scalar* xd,
                          const Scalar* xdd, const Vector3<Scalar>& gravity, Scalar* tau, Scalar* velocity_terms,
                          Scalar* gravity_terms, typename BodyWorkspace<Scalar>::MatrixX* dtau_dx,
                          typename BodyWorkspace<Scalar>::MatrixX* dtau_dxd)
{
  forwardKinematics(model, ws, x);
  detail::compositeInertias(model, ws);
  const Scalar* nu = motionRates(model, ws, xd);
  const Scalar* nu_dot = motionAccelerations(model, ws, xd, xdd);
  if (dtau_dx)
  {
    inverseDynamicsDerivativesInMotion(model, ws, nu, nu_dot, gravity, *dtau_dx, *dtau_dxd);
    if (model.hasFreeRoot())
      detail::inverseDynamicsDerivativesToCoordinates(model, ws, xd, xdd, *dtau_dx, *dtau_dxd);
    std::copy(ws.tau.data(), ws.tau.data() + model.coordinates, tau);
  }
  else
    inverseDynamicsInMotion(model, ws, nu, nu_dot, gravity, tau, /*inertias_ready=*/true);
  detail::gravityTermsFromComposites(model, ws, gravity, gravity_terms);
  inverseDynamicsInMotion(model, ws, nu, motionAccelerations(model, ws, xd, static_cast<const Scalar*>(nullptr)),
                          Vector3<Scalar>::Zero().eval(), velocity_terms, /*inertias_ready=*/true);
  for (Scalar* out : { tau, velocity_terms, gravity_terms })
    forceToCoordinates(model, ws, out);
}

extern template void inverseDynamicsTerms<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                                  const double*, const double*, const Vector3<double>&, double*,
                                                  double*, double*, Eigen::MatrixXd*, Eigen::MatrixXd*);
extern template void inverseDynamicsDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                                        const double*, const double*, const Vector3<double>&,
                                                        Eigen::MatrixXd&, Eigen::MatrixXd&);

}  // namespace diff_rigid_body
