// Inverse dynamics of a body by the recursive Newton-Euler algorithm
// (Featherstone 2008, ch. 5), in the fixed frame about the reference point r
// (spatial.h, kinematics.h): the generalized forces
//   tau = M(x) x'' + c(x, x') + g(x)
// of docs/interface.md, Version 3, for x' and x'' of d values each.
//
// It runs in motion coordinates (body_model.h): nu = A x', nu' = A x'' + Q,
// tau = A^T tau_nu (motion_coordinates.h). Forward, over the dofs k (parents
// first), with q'_k = m_k nu[c_k] and q''_k = m_k nu'[c_k] the dof's
// velocity and acceleration (m_k its mimic multiplier):
//   v_k = v_parent + S_k q'_k
//   a_k = a_parent + S_k q''_k + v_carrier x S_k q'_k   (dS_k/dt = v_carrier x S_k)
// where the carrier is the parent (then v_carrier x S_k = v_k x S_k), but for
// a free root's rotations, whose axes only move with the COM: for them the
// sum is (0, t' x w), and a_root = (w', t'' + t' x w) at r = t.
// from v = 0 and a = (0, -gamma) above the root: gravity gamma [m/s^2] enters
// as an upward acceleration of the fixed frame. A segment moves with its last
// dof; its Newton-Euler force, with Y_s its inertia about r,
//   f_s = Y_s a_s + v_s x* Y_s v_s,
// is summed over each subtree (children first), and
//   tau[c_k] += m_k S_k . F_seg(k).
// For a free root, tau_nu's entries are (n, f): the moment n about its COM
// and the force f, fixed axes, so tau's are (T^T n, f). The velocity terms are c = tau(x, x', 0) with gamma = 0, the gravity
// terms g = tau(x, 0, 0) (docs/derivation.md derives both for one free
// body from the Lagrangian). O(dofs); nothing is inverted, so every term
// stays finite at gimbal lock.
#pragma once

#include "diff_rigid_body/algorithm/kinematics.h"
#include "diff_rigid_body/multibody/motion_coordinates.h"

namespace diff_rigid_body
{
namespace detail
{
/// ws.body_inertia: each segment's own inertia about ws.r.
template <typename Scalar>
void segmentInertias(const BodyModel& model, BodyWorkspace<Scalar>& ws)
{
  for (std::size_t s = 0; s < model.segments.size(); ++s)
  {
    const MassProperties& own = model.segments[s].inertia;
    ws.body_inertia[s] = own.mass > 0.0 ? spatial::inertiaAbout(ws.r, ws.R[s], ws.p[s], own.mass, own.com, own.inertia) :
                                          Inertia<Scalar>();
  }
}

/// Forward pass: per dof velocity and acceleration (ws.dof_velocity,
/// ws.dof_acceleration) from the kinematics in ws, at nu and nu' (null: zeros).
template <typename Scalar>
void propagateMotion(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* xd, const Scalar* xdd,
                     const Vector3<Scalar>& gravity)
{
  Motion<Scalar> base_acceleration;
  base_acceleration.v = -gravity;
  for (std::size_t k = 0; k < model.dofs.size(); ++k)
  {
    const Dof& dof = model.dofs[k];
    const Motion<Scalar>& S = ws.S[k];
    const Scalar qd = xd ? Scalar(dof.multiplier) * xd[dof.coordinate] : Scalar(0);
    const Scalar qdd = xdd ? Scalar(dof.multiplier) * xdd[dof.coordinate] : Scalar(0);
    Motion<Scalar>& v = ws.dof_velocity[k];
    Motion<Scalar>& a = ws.dof_acceleration[k];
    if (dof.parent >= 0)
    {
      v = ws.dof_velocity[static_cast<std::size_t>(dof.parent)];
      a = ws.dof_acceleration[static_cast<std::size_t>(dof.parent)];
    }
    else
    {
      v = Motion<Scalar>();
      a = base_acceleration;
    }
    v.w += S.w * qd;
    v.v += S.v * qd;
    const Motion<Scalar> bias =
        dof.carrier == dof.parent ? spatial::crossMotion(v, S) :
        dof.carrier < 0           ? Motion<Scalar>() :
                                    spatial::crossMotion(ws.dof_velocity[static_cast<std::size_t>(dof.carrier)], S);
    a.w += S.w * qdd + bias.w * qd;
    a.v += S.v * qdd + bias.v * qd;
  }
}

/// Backward pass: ws.subtree_force per segment (its subtree's Newton-Euler
/// force) and tau, from the motion in ws.
template <typename Scalar>
void accumulateForces(const BodyModel& model, BodyWorkspace<Scalar>& ws, Scalar* tau)
{
  for (std::size_t s = 0; s < model.segments.size(); ++s)
  {
    const Segment& segment = model.segments[s];
    const std::size_t last = static_cast<std::size_t>(segment.first_dof + segment.dof_count - 1);
    const Motion<Scalar>& v = ws.dof_velocity[last];
    const Force<Scalar> inertial = spatial::momentum(ws.body_inertia[s], ws.dof_acceleration[last]);
    const Force<Scalar> gyroscopic = spatial::crossForce(v, spatial::momentum(ws.body_inertia[s], v));
    ws.subtree_force[s].n = inertial.n + gyroscopic.n;
    ws.subtree_force[s].f = inertial.f + gyroscopic.f;
  }
  for (std::size_t s = model.segments.size(); s-- > 1;)
  {
    Force<Scalar>& parent = ws.subtree_force[static_cast<std::size_t>(model.segments[s].parent)];
    parent.n += ws.subtree_force[s].n;
    parent.f += ws.subtree_force[s].f;
  }
  std::fill(tau, tau + model.coordinates, Scalar(0));
  for (std::size_t k = 0; k < model.dofs.size(); ++k)
  {
    const Dof& dof = model.dofs[k];
    tau[dof.coordinate] +=
        Scalar(dof.multiplier) * spatial::power(ws.S[k], ws.subtree_force[static_cast<std::size_t>(dof.segment)]);
  }
}
}  // namespace detail

/// tau_nu = H nu' + (c + g in nu) into `tau` (d values) from the
/// kinematics in ws (forwardKinematics at x), at nu and nu' (null: zeros).
/// gravity: gamma in the fixed frame [m/s^2].
/// `inertias_ready`: ws.body_inertia already holds them for this kinematics
/// (crba computed them).
template <typename Scalar>
void inverseDynamicsInMotion(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* nu,
                             const Scalar* nu_dot, const Vector3<Scalar>& gravity, Scalar* tau,
                             bool inertias_ready = false)
{
  if (!inertias_ready)
    detail::segmentInertias(model, ws);
  detail::propagateMotion(model, ws, nu, nu_dot, gravity);
  detail::accumulateForces(model, ws, tau);
}

/// tau = M(x) x'' + c(x, x') + g(x) at (x, x', x'') into `tau` (d values);
/// a null xd or xdd means zeros.
template <typename Scalar>
void inverseDynamics(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, const Scalar* xd,
                     const Scalar* xdd, const Vector3<Scalar>& gravity, Scalar* tau)
{
  forwardKinematics(model, ws, x);
  const Scalar* nu_dot = motionAccelerations(model, ws, xd, xdd);
  inverseDynamicsInMotion(model, ws, motionRates(model, ws, xd), nu_dot, gravity, tau);
  forceToCoordinates(model, ws, tau);
}

namespace detail
{
/// g_nu = -sum m_k S_k . Ic_seg(k) (0, gamma) (at rest every segment
/// accelerates by (0, -gamma): one product per dof, no pass) into `g`,
/// from the composite inertias in ws.
template <typename Scalar>
void gravityTermsFromComposites(const BodyModel& model, const BodyWorkspace<Scalar>& ws,
                                const Vector3<Scalar>& gravity, Scalar* g)
{
  Motion<Scalar> fall;
  fall.v = -gravity;
  std::fill(g, g + model.coordinates, Scalar(0));
  for (std::size_t k = 0; k < model.dofs.size(); ++k)
  {
    const Dof& dof = model.dofs[k];
    g[dof.coordinate] += Scalar(dof.multiplier) *
                         spatial::power(ws.S[k], spatial::momentum(ws.composite[static_cast<std::size_t>(dof.segment)], fall));
  }
}
}  // namespace detail

extern template void inverseDynamics<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                             const double*, const double*, const Vector3<double>&, double*);

}  // namespace diff_rigid_body
