// Analytic derivatives of inverse dynamics (rnea.h), dtau/dx and dtau/dx',
// in the fixed frame about r (after Carpentier and Mansard, "Analytical
// derivatives of rigid body dynamics algorithms", RSS 2018; derived anew for
// these coordinates in docs/derivation.md).
//
// Moving dof j (its value, at fixed x' and x'') carries its subtree: unit
// motions, inertias and the Newton-Euler forces f_s = Y_s a_s + v_s x* Y_s v_s
// of the segments it moves change as if carried by S_j, except that their
// velocity and acceleration also lose what dof j's own motion put there:
//   df_s/dq_j  = S_j x* f_s - Y_s w_j - B_s u_j,
//   df_s/dq'_j = B_s S_j - 2 Y_s u_j,
// with u_j = S_j x v_j, w_j = S_j x a_j - u_j x v_j (v_j, a_j: the motion of
// what dof j moves, gravity included in a_j), and B_s the linear map
//   B_s m = Y_s (m x v_s) + m x* (Y_s v_s) + v_s x* (Y_s m)
//         = (T_s m.w, -2 p_s x m.w),
//   T_s = [w]I - I[w] - [v][h] - [h][v] - [I w + h x v],  p_s = m v + w x h,
// for v_s = (w, v) and Y_s = (m, h, I): B_s reads only the angular part of
// its argument. Summed over subtrees (Ic, F, T^c, p^c) and paired with the
// unit motions (tau_i = S_i . F_seg(i)), for dofs i, j:
//   j an ancestor of i, or i:   dtau_i/dq_j  = -F^M_i . w_j - G_i . u_j.w
//                               dtau_i/dq'_j =  G_i . S_j.w - 2 F^M_i . u_j
//   i strictly above j:         dtau_i/dq_j  =  S_i . (S_j x* F_j - Ic_j w_j - B^c_j u_j)
//                               dtau_i/dq'_j =  S_i . (B^c_j S_j - 2 Ic_j u_j)
// where F^M_i = Ic_i S_i (the CRBA's momentum) and G_i = T^c_i^T S_i.w -
// 2 S_i.v x p^c_i (the angular part of B^c_i^T S_i); every other pair is 0.
// In x: d/dx_c sums m_j d/dq_j over the dofs j that x_c drives, and
// tau[c_i] carries m_i. Work: O(dofs x depth), no 6 x 6 matrix.
//
// dtau/dx' = 2 C, the Christoffel Coriolis matrix of interface.md, Version 3.
#pragma once

#include "diff_rigid_body/crba.h"
#include "diff_rigid_body/rnea.h"

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
    const std::size_t s = static_cast<std::size_t>(model.dofs[k].segment);
    const Motion<Scalar>& S = ws.S[k];
    auto& terms = ws.dof_terms[k];
    terms.u = spatial::crossMotion(S, ws.dof_velocity[k]);
    const Motion<Scalar> Sa = spatial::crossMotion(S, ws.dof_acceleration[k]);
    const Motion<Scalar> uv = spatial::crossMotion(terms.u, ws.dof_velocity[k]);
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
    const Force<Scalar> Iu = spatial::momentum(ws.composite[s], terms.u);
    moved_rate[k].n = BS.n - Scalar(2) * Iu.n;
    moved_rate[k].f = BS.f - Scalar(2) * Iu.f;
  }
}
}  // namespace detail

/// dtau/dx and dtau/dx' (d x d, column-major Eigen matrices of ws's scalar:
/// row = tau component, column = coordinate) at (x, x', x''), and tau into
/// ws.tau. Also leaves the kinematics, composite inertias and momenta in ws.
template <typename Scalar>
void inverseDynamicsDerivatives(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, const Scalar* xd,
                                const Scalar* xdd, const Vector3<Scalar>& gravity,
                                typename BodyWorkspace<Scalar>::MatrixX& dtau_dx,
                                typename BodyWorkspace<Scalar>::MatrixX& dtau_dxd)
{
  forwardKinematics(model, ws, x);
  detail::compositeInertias(model, ws);
  inverseDynamicsFromKinematics(model, ws, xd, xdd, gravity, ws.tau.data(), /*inertias_ready=*/true);
  detail::velocityRates(model, ws);
  std::vector<Force<Scalar>>& moved_rate = ws.momentum_rate;
  detail::dofDerivativeTerms(model, ws, moved_rate);
  dtau_dx.setZero();
  dtau_dxd.setZero();
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
      dtau_dx(dof_i.coordinate, dof_j.coordinate) -=
          m * (spatial::power(terms_j.w, FM) + spatial::dot(terms_i.gamma.n, terms_j.u.w));
      dtau_dxd(dof_i.coordinate, dof_j.coordinate) +=
          m * (spatial::dot(terms_i.gamma.n, ws.S[static_cast<std::size_t>(j)].w) -
               Scalar(2) * spatial::power(terms_j.u, FM));
      if (j == static_cast<int>(i))
        continue;
      // i below j: row j, column i.
      dtau_dx(dof_j.coordinate, dof_i.coordinate) +=
          m * spatial::power(ws.S[static_cast<std::size_t>(j)], terms_i.moved);
      dtau_dxd(dof_j.coordinate, dof_i.coordinate) +=
          m * spatial::power(ws.S[static_cast<std::size_t>(j)], moved_rate[i]);
    }
  }
}

extern template void inverseDynamicsDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                                        const double*, const double*, const Vector3<double>&,
                                                        Eigen::MatrixXd&, Eigen::MatrixXd&);

}  // namespace diff_rigid_body
