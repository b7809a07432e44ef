// Frame and centre-of-mass Jacobians of a body (README, "Frames and centre
// of mass"): for a link frame F (a moving link, or a link merged into one)
// with pose (R_F, p_F) in the fixed frame, at x and x':
//
//   J = d(v, w)/dx'   (6 x d, rows linear then angular),   J x' = (v, w),
//   bias = the frame's classical acceleration at x'' = 0, so that its
//          acceleration is J x'' + bias,
//
// in the three references users meet (Pinocchio's meanings):
//   WORLD                v of the body point at the fixed frame's origin, fixed axes;
//   LOCAL_WORLD_ALIGNED  v of F's origin, fixed axes;
//   LOCAL                v of F's origin, F's axes (R_F^T on both rows).
// With the segment's columns (V_c, W_c) (segment_columns.h: dp/dx_c =
// V_c + W_c x (p - r) for a point p of the segment) and the point
// P = p_F (LOCAL, LOCAL_WORLD_ALIGNED) or 0 (WORLD):
//   J_c = (V_c + W_c x (P - r), W_c),
// and with the segment's spatial velocity (w, v_r) and acceleration
// (w', a_r) at r from a Newton-Euler pass at nu' = Q, without gravity
// (rnea.h: x'' = 0), v_P = v_r + w x (P - r), a_P = a_r + w' x (P - r):
//   bias = (a_P + w x v_P, w')          (getFrameClassicalAcceleration).
// Columns are d/dx', for a free root the Euler-angle rates (J = J_nu A).
//
// Centre of mass c of a body of mass m: c = r + h / m from its composite
// inertia (crba.h); its Jacobian column by dof k is
//   dc/dnu_k = m_k (Ic_k S_k).f / m = m_k (m_k' S_k.v + S_k.w x h_k) / m
// (Ic_k = (m_k', h_k, .) the inertia of what dof k moves), through the chart;
// its bias is the rate of linear momentum at x'' = 0 over m: the linear part
// of the root's subtree force from the same Newton-Euler pass.
#pragma once

#include <cstdint>
#include <vector>

#include "diff_rigid_body/multibody/body_workspace.h"

namespace diff_rigid_body
{
/// The reference a frame Jacobian and its bias are expressed in; the values
/// are the wire's (GetFrameJacobians.srv).
enum class FrameReference : std::uint8_t
{
  World = 0,
  Local = 1,
  LocalWorldAligned = 2,
};

/// Marks in `needed` (one entry per segment) the segments that frame `link`
/// (an index into model.links) hangs from: its segment and its ancestors,
/// all that forwardKinematicsOf must place for frameJacobian without bias.
void markSupport(const BodyModel& model, std::size_t link, std::vector<char>& needed);

/// Frame `link` (an index into model.links) at the kinematics in ws
/// (forwardKinematics, or forwardKinematicsOf over markSupport): its pose (12 values: position, then R_F row-major)
/// into pose12, its Jacobian (6 x d row-major) into jacobian unless null,
/// and its classical acceleration bias (6) into bias unless null, which
/// needs the motion of frameMotion at (x, x').
void frameJacobian(const BodyModel& model, BodyWorkspace<double>& ws, std::size_t link, FrameReference reference,
                   double* pose12, double* jacobian, double* bias);

/// The segment velocities and accelerations at x'' = 0 without gravity
/// (ws.dof_velocity, ws.dof_acceleration) at (x, x') from the kinematics in
/// ws, which must be forwardKinematics' (every segment: the pass reads every
/// dof's motion), for the biases; null xd means zeros.
void frameMotion(const BodyModel& model, BodyWorkspace<double>& ws, const double* xd);

/// The body's centre of mass at x into com (3, fixed frame), its Jacobian
/// (3 x d row-major) into jacobian unless null, and its bias (3) into bias
/// unless null, at (x, x') (null xd: zeros). Returns the body's mass; 0
/// means a massless body, whose COM is undefined (nothing written).
double centerOfMass(const BodyModel& model, BodyWorkspace<double>& ws, const double* x, const double* xd,
                    double* com, double* jacobian, double* bias);

}  // namespace diff_rigid_body
