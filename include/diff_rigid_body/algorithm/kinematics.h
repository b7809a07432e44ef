// Forward kinematics of a body (body_model.h): every segment frame and every
// dof's unit motion at x, templated on the scalar (double; std::complex for
// the complex step; mpfr::mpreal for references).
//
// Segment frames, with (R, p) a frame's pose in the fixed frame
// (p_fixed = R p_frame + p):
//   free root:        R = Rz(psi) Ry(theta) Rx(phi),  p = t = (tx, ty, tz)
//   joint segment s:  (Rj, pj) = (R_parent Rpl, R_parent ppl + p_parent), the
//                     joint frame ((Rpl, ppl) its placement; at a fixed-base
//                     root the placement itself), and with the joint value
//                     s = multiplier x[coordinate] + offset about or along
//                     the world axis a = Rj axis:
//                       revolute:   R = Rj Rot(axis, s),  p = pj
//                       prismatic:  R = Rj,               p = pj + s a
// Unit motions at the reference point r (the free root's COM t, or a fixed-base
// root's joint origin: near the body, so that nothing cancels far from the
// fixed frame's origin):
//   revolute dof:   (a, a x (r - pj))     prismatic dof:  (0, a)
//   free root:      tx, ty, tz: (0, e_x), (0, e_y), (0, e_z);
//                   wx, wy, wz: (e_x, 0), (e_y, 0), (e_z, 0), rotations
//                   about the fixed axes through t (motion coordinates,
//                   body_model.h), with the chart T(phi, theta, psi) in ws.chart.
// A point p of segment s then moves with dp/dnu_c = sum over the dofs k on
// its path to the root that nu_c drives of multiplier_k (S_k.v + S_k.w x (p - r)),
// and dp/dx = (dp/dnu) A (motion_coordinates.h).
//
// In double, the sines and cosines of every joint angle and of the free
// root's angles come from one vectorised call (sinCos, rpy.h).
#pragma once

#include <cmath>
#include <type_traits>
#include <vector>

#include <Eigen/Geometry>

#include "diff_rigid_body/multibody/body_workspace.h"
#include "diff_rigid_body/algorithm/free_body/pose.h"
#include "diff_rigid_body/multibody/free_root_chart.h"
#include "diff_rigid_body/multibody/rpy.h"

namespace diff_rigid_body
{
namespace detail
{
/// The joint value of segment s: multiplier x[coordinate] + offset.
template <typename Scalar>
Scalar jointValue(const BodyModel& model, const Segment& segment, const Scalar* x)
{
  const Dof& dof = model.dofs[static_cast<std::size_t>(segment.first_dof)];
  return Scalar(dof.multiplier) * x[dof.coordinate] + Scalar(segment.offset);
}

/// Sines and cosines of every revolute joint's value (in its angle slot) and
/// of a free root's phi, theta, psi (the three slots after them).
template <typename Scalar>
void jointTrigonometry(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x)
{
  const std::size_t revolute = model.revolute_segments.size();
  for (std::size_t k = 0; k < revolute; ++k)
    ws.joint_angle[k] = jointValue(model, model.segments[static_cast<std::size_t>(model.revolute_segments[k])], x);
  std::size_t count = revolute;
  if (model.hasFreeRoot())
    for (int k = 0; k < 3; ++k)
      ws.joint_angle[count++] = x[PHI + k];
  if constexpr (std::is_same<Scalar, double>::value)
    sinCos(ws.joint_angle.data(), count, ws.joint_sine.data(), ws.joint_cosine.data());
  else
  {
    using std::cos;
    using std::sin;
    for (std::size_t k = 0; k < count; ++k)
    {
      ws.joint_sine[k] = sin(ws.joint_angle[k]);
      ws.joint_cosine[k] = cos(ws.joint_angle[k]);
    }
  }
}

/// jointTrigonometry for the revolute segments s with needed[s] != 0 and a
/// free root's angles; the other revolute slots are stale. The needed angles
/// are gathered to the front of ws.joint_angle, done by one sinCos, and
/// scattered back to their slots from the last (a slot is never before its
/// compact index, so nothing is overwritten before it is read).
inline void neededJointTrigonometry(const BodyModel& model, BodyWorkspace<double>& ws, const double* x,
                                    const std::vector<char>& needed)
{
  const std::size_t revolute = model.revolute_segments.size();
  std::size_t count = 0;
  for (std::size_t k = 0; k < revolute; ++k)
  {
    const std::size_t s = static_cast<std::size_t>(model.revolute_segments[k]);
    if (needed[s])
      ws.joint_angle[count++] = jointValue(model, model.segments[s], x);
  }
  if (model.hasFreeRoot())
    for (int k = 0; k < 3; ++k)
      ws.joint_angle[count++] = x[PHI + k];
  sinCos(ws.joint_angle.data(), count, ws.joint_sine.data(), ws.joint_cosine.data());
  std::size_t compact = count;
  const auto move_to = [&](std::size_t slot) {
    --compact;
    ws.joint_sine[slot] = ws.joint_sine[compact];
    ws.joint_cosine[slot] = ws.joint_cosine[compact];
  };
  if (model.hasFreeRoot())
    for (int k = 2; k >= 0; --k)
      move_to(revolute + static_cast<std::size_t>(k));
  for (std::size_t k = revolute; k-- > 0 && compact > 0;)
    if (needed[static_cast<std::size_t>(model.revolute_segments[k])])
      move_to(k);
}

/// R Rot(axis, angle) from its sine and cosine: for axis = +-e_k only two
/// columns change (i, j, k cyclic, sigma = axis_k):
///   col_i' = c col_i + sigma s col_j,   col_j' = c col_j - sigma s col_i;
/// otherwise R times Rodrigues' c I + s [a]x + (1 - c) a a^T.
template <typename Scalar>
Matrix3<Scalar> rotatedAboutAxis(const Matrix3<Scalar>& R, const Segment& segment, const Scalar& sine,
                                 const Scalar& cosine)
{
  const int k = segment.axis_index;
  if (k >= 0)
  {
    const Scalar sn = Scalar(segment.axis[k]) * sine;
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    Matrix3<Scalar> out;
    out.col(k) = R.col(k);
    out.col(i) = cosine * R.col(i) + sn * R.col(j);
    out.col(j) = cosine * R.col(j) - sn * R.col(i);
    return out;
  }
  const Eigen::Vector3d& a = segment.axis;
  const Scalar one_minus_c = Scalar(1) - cosine;
  Matrix3<Scalar> rotation;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      rotation(r, c) = one_minus_c * a[r] * a[c];
  for (int r = 0; r < 3; ++r)
    rotation(r, r) += cosine;
  rotation(0, 1) -= sine * a[2];
  rotation(1, 0) += sine * a[2];
  rotation(0, 2) += sine * a[1];
  rotation(2, 0) -= sine * a[1];
  rotation(1, 2) -= sine * a[0];
  rotation(2, 1) += sine * a[0];
  return R * rotation;
}

/// Frame and unit motion of joint segment s from its joint frame (Rj, pj).
template <typename Scalar>
void placeJointSegment(const BodyModel& model, BodyWorkspace<Scalar>& ws, std::size_t s, const Matrix3<Scalar>& Rj,
                       const Vector3<Scalar>& pj, const Scalar* x)
{
  const Segment& segment = model.segments[s];
  const int k = segment.axis_index;
  const Vector3<Scalar> a = k >= 0 ? Vector3<Scalar>(Scalar(segment.axis[k]) * Rj.col(k)) :
                                     Vector3<Scalar>(Rj * segment.axis.template cast<Scalar>());
  Motion<Scalar>& S = ws.S[static_cast<std::size_t>(segment.first_dof)];
  if (segment.joint_type == JointType::Revolute)
  {
    const std::size_t slot = static_cast<std::size_t>(segment.angle_slot);
    ws.R[s] = rotatedAboutAxis(Rj, segment, ws.joint_sine[slot], ws.joint_cosine[slot]);
    ws.p[s] = pj;
    S.w = a;
    S.v = spatial::cross(a, Vector3<Scalar>(ws.r - pj));
  }
  else
  {
    ws.R[s] = Rj;
    ws.p[s] = pj + a * jointValue(model, segment, x);
    S.w.setZero();
    S.v = a;
  }
}

/// The free root's frame (R(phi, theta, psi), t), its chart (ws.chart) and
/// its six unit motions at r = t: tx, ty, tz: (0, e_k); wx, wy, wz: (e_k, 0).
template <typename Scalar>
void placeFreeRoot(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x)
{
  const std::size_t n = model.revolute_segments.size();
  const RpyTrig<Scalar> trig(&ws.joint_sine[n], &ws.joint_cosine[n]);
  ws.R[0] = rpyToMatrix(trig);
  ws.p[0] << x[TX], x[TY], x[TZ];
  ws.r = ws.p[0];
  ws.chart = FreeRootChart<Scalar>(trig);
  Motion<Scalar>* S = &ws.S[static_cast<std::size_t>(model.segments[0].first_dof)];
  for (int k = 0; k < 3; ++k)
  {
    S[k].w.setZero();
    S[k].v = Vector3<Scalar>::Unit(k);
    S[3 + k].w = Vector3<Scalar>::Unit(k);
    S[3 + k].v.setZero();
  }
}
}  // namespace detail

namespace detail
{
/// The root and every later segment s with needed(s) placed at x (a set
/// closed under parents: a needed segment's parent is needed), from the
/// sines and cosines in ws (jointTrigonometry of at least those segments).
template <typename Scalar, typename Needed>
void placeSegments(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, Needed&& needed)
{
  const Segment& root = model.segments[0];
  if (root.joint_type == JointType::Free)
    placeFreeRoot(model, ws, x);
  else
  {
    const Matrix3<Scalar> Rj = root.placement_rotation.template cast<Scalar>();
    const Vector3<Scalar> pj = root.placement_translation.template cast<Scalar>();
    ws.r = pj;
    placeJointSegment(model, ws, 0, Rj, pj, x);
  }
  for (std::size_t s = 1; s < model.segments.size(); ++s)
  {
    if (!needed(s))
      continue;
    const Segment& segment = model.segments[s];
    const std::size_t parent = static_cast<std::size_t>(segment.parent);
    const Vector3<Scalar> pj = ws.R[parent] * segment.placement_translation.template cast<Scalar>() + ws.p[parent];
    if (segment.placement_rotates)
      placeJointSegment(model, ws, s, Matrix3<Scalar>(ws.R[parent] * segment.placement_rotation.template cast<Scalar>()),
                        pj, x);
    else
      placeJointSegment(model, ws, s, ws.R[parent], pj, x);  // writes ws.R[s] only: no alias
  }
}
}  // namespace detail

/// Every segment frame (ws.R, ws.p), dof motion (ws.S) and the reference
/// point (ws.r) at x (model.coordinates values); see the header comment.
template <typename Scalar>
void forwardKinematics(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x)
{
  detail::jointTrigonometry(model, ws, x);
  detail::placeSegments(model, ws, x, [](std::size_t) { return true; });
}

/// forwardKinematics of the segments with needed[s] != 0 only (closed under
/// parents, e.g. the path from the root to the links asked for: what a
/// frame's pose and Jacobian read); the other segments' entries are stale.
inline void forwardKinematicsOf(const BodyModel& model, BodyWorkspace<double>& ws, const double* x,
                                const std::vector<char>& needed)
{
  detail::neededJointTrigonometry(model, ws, x, needed);
  detail::placeSegments(model, ws, x, [&](std::size_t s) { return needed[s] != 0; });
}

/// cos(theta) of a free root at the x of ws's last forwardKinematics(Of)
/// (the middle one of its three angle slots, after the revolute joints'); 1
/// for a fixed base.
inline double rootCosTheta(const BodyModel& model, const BodyWorkspace<double>& ws)
{
  return model.hasFreeRoot() ? ws.joint_cosine[model.revolute_segments.size() + (THETA - PHI)] : 1.0;
}

/// Whether every frame, unit motion and the reference point are finite (a
/// prismatic joint at 1e308 overflows them).
bool kinematicsAreFinite(const BodyModel& model, const BodyWorkspace<double>& ws);

/// Pose in the fixed frame of every link of the body at x, in
/// model.links order: X_segment(x) T(link_origin) pose_in_segment_link. A
/// free object's segment pose is free_body/pose.h's (R(q), t), as its
/// vertex queries use it.
void linkPoses(const BodyModel& model, BodyWorkspace<double>& ws, const double* x,
               std::vector<Eigen::Isometry3d>& poses);

extern template void forwardKinematics<double>(const BodyModel&, BodyWorkspace<double>&, const double*);

}  // namespace diff_rigid_body
