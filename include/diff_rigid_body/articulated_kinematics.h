// Kinematics and the joint-space mass matrix of an articulated body,
// templated on the scalar (double, std::complex<double> for complex-step
// derivatives, mpfr::mpreal for references, Eigen's AutoDiffScalar for dM/dx).
//
// Motion of the body, per coordinate x_c, as a twist in the fixed frame
// taken at the body's reference point r (the root COM t for a floating root,
// the root joint's origin for a fixed-base root; near the body, so that the
// sums below do not cancel far from the fixed frame's origin):
//   revolute joint, world axis a through point o:  w = a, v = a x (r - o)
//   prismatic joint, world axis a:                 w = 0, v = a
//   floating root, Euler angle k:                  w = T_k (column k of T(r)), v = 0
//   floating root, translation k:                  w = 0,  v = e_k
// A point p moved by the coordinate moves at dp/dx_c = sum m_j (v_j + w_j x (p - r))
// over the joints j on its path from the root that x_c drives (m_j: the
// mimic multiplier, 1 otherwise).
//
// Kinetic energy 1/2 x'^T M x' = sum over segments of 1/2 (m |v_COM|^2 + w^T I w).
// With a segment's spatial inertia about r, (m, h = m (c - r),
// I_r = I_c + m (|d|^2 I3 - d d^T)), d = c - r:
//   S_a^T Lambda S_b = w_a . I_r w_b + m v_a . v_b - v_a . (h x w_b) - v_b . (h x w_a)
//                    = w_a . (I_r w_b + h x v_b) + v_a . (m v_b - h x w_b)
// and M(c_a, c_b) sums it over joint pairs a, b and the segments that both
// move (composite inertia of the deeper one's subtree).
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/articulated_body.h"
#include "diff_rigid_body/body_pose.h"
#include "diff_rigid_body/rpy.h"

namespace diff_rigid_body
{
/// Pose of a segment's link frame in the fixed frame: p_fixed = R p_link + p.
template <typename Scalar>
struct SegmentFrame
{
  Matrix3<Scalar> R;
  Vector3<Scalar> p;
};

/// A coordinate's twist at the reference point (see the header comment).
template <typename Scalar>
struct Twist
{
  Vector3<Scalar> w;
  Vector3<Scalar> v;
};

/// Everything the queries need from x, computed once per configuration.
template <typename Scalar>
struct ArticulatedPose
{
  std::vector<SegmentFrame<Scalar>> frames;  ///< per segment
  std::vector<Twist<Scalar>> joint_twists;   ///< per segment: its joint's twist (unused for a floating root)
  Matrix3<Scalar> root_T;                    ///< floating root: T(phi, theta, psi), Euler rates -> world w
  Vector3<Scalar> reference;                 ///< r [m]
};

namespace detail
{
template <typename Scalar>
Matrix3<Scalar> castMatrix(const Eigen::Matrix3d& m)
{
  return m.template cast<Scalar>();
}

/// Rotation by angle s about the unit axis a (Rodrigues):
/// cos s I + sin s [a]x + (1 - cos s) a a^T.
template <typename Scalar>
Matrix3<Scalar> axisRotation(const Eigen::Vector3d& a, const Scalar& s)
{
  using std::cos;
  using std::sin;
  const Scalar c = cos(s), sn = sin(s);
  const Scalar one_minus_c = Scalar(1) - c;
  Matrix3<Scalar> R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      R(i, j) = one_minus_c * a[i] * a[j];
  for (int i = 0; i < 3; ++i)
    R(i, i) += c;
  R(0, 1) -= sn * a[2];
  R(1, 0) += sn * a[2];
  R(0, 2) += sn * a[1];
  R(2, 0) -= sn * a[1];
  R(1, 2) -= sn * a[0];
  R(2, 1) += sn * a[0];
  return R;
}

/// k for an axis that is exactly +-e_k (as most URDF axes are), else -1.
inline int coordinateAxis(const Eigen::Vector3d& a)
{
  for (int k = 0; k < 3; ++k)
    if (std::abs(a[k]) == 1.0)
      return k;
  return -1;
}

/// R * rotation(s about the unit axis a), with R the joint frame's rotation.
/// For a = +-e_k only two columns change (i, j, k cyclic, sigma = a_k):
///   col_i' = c col_i + sigma s col_j,   col_j' = c col_j - sigma s col_i.
template <typename Scalar>
Matrix3<Scalar> rotateAboutJointAxis(const Matrix3<Scalar>& R, const Eigen::Vector3d& a, const Scalar& s)
{
  const int k = coordinateAxis(a);
  if (k < 0)
    return R * axisRotation(a, s);
  using std::cos;
  using std::sin;
  const Scalar c = cos(s), sn = Scalar(a[k]) * sin(s);
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  Matrix3<Scalar> out;
  out.col(k) = R.col(k);
  out.col(i) = c * R.col(i) + sn * R.col(j);
  out.col(j) = c * R.col(j) - sn * R.col(i);
  return out;
}

/// a . b without conjugation (Eigen's dot and cross conjugate complex
/// scalars, which would break complex-step derivatives; detail::cross of
/// body_pose.h does not).
template <typename Scalar>
Scalar dot3(const Vector3<Scalar>& a, const Vector3<Scalar>& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// The joint value of a segment: multiplier x[coordinate] + offset.
template <typename Scalar>
Scalar jointValue(const Segment& segment, const Scalar* x)
{
  return Scalar(segment.multiplier) * x[segment.coordinate] + Scalar(segment.offset);
}
}  // namespace detail

/// Frames and twists of every segment at x (len = body.dofs()).
template <typename Scalar>
ArticulatedPose<Scalar> articulatedPose(const ArticulatedBody& body, const Scalar* x)
{
  ArticulatedPose<Scalar> pose;
  const std::size_t n = body.segments.size();
  pose.frames.resize(n);
  pose.joint_twists.resize(n);
  for (std::size_t s = 0; s < n; ++s)
  {
    const Segment& segment = body.segments[s];
    SegmentFrame<Scalar>& frame = pose.frames[s];
    if (segment.parent < 0 && body.floating_root)
    {
      const RpyTrig<Scalar> trig(x[PHI], x[THETA], x[PSI]);
      frame.R = rpyToMatrix(trig);
      pose.root_T = angularVelocityMatrixWorld(trig);
      pose.reference << x[TX], x[TY], x[TZ];
      frame.p = pose.reference - frame.R * segment.mass_properties.com.template cast<Scalar>();
      continue;
    }
    // Joint frame in the fixed frame: parent * origin (or origin at a fixed-base root).
    Matrix3<Scalar> joint_R = detail::castMatrix<Scalar>(segment.origin.linear());
    Vector3<Scalar> joint_p = segment.origin.translation().template cast<Scalar>();
    if (segment.parent >= 0)
    {
      const SegmentFrame<Scalar>& parent = pose.frames[static_cast<std::size_t>(segment.parent)];
      joint_p = parent.R * joint_p + parent.p;
      joint_R = parent.R * joint_R;
    }
    else
      pose.reference = joint_p;
    const Scalar value = detail::jointValue(segment, x);
    const int k = detail::coordinateAxis(segment.axis);
    const Vector3<Scalar> axis = k >= 0 ? Vector3<Scalar>(Scalar(segment.axis[k]) * joint_R.col(k)) :
                                          Vector3<Scalar>(joint_R * segment.axis.template cast<Scalar>());
    Twist<Scalar>& twist = pose.joint_twists[s];
    if (segment.motion == JointMotion::Revolute)
    {
      frame.R = detail::rotateAboutJointAxis(joint_R, segment.axis, value);
      frame.p = joint_p;
      twist.w = axis;
      twist.v = detail::cross(axis, Vector3<Scalar>(pose.reference - joint_p));
    }
    else
    {
      frame.R = joint_R;
      frame.p = joint_p + axis * value;
      twist.w.setZero();
      twist.v = axis;
    }
  }
  return pose;
}

namespace detail
{
/// Spatial inertia about the reference point: mass, first moment h = m (c - r),
/// and the rotational inertia about r in fixed-frame axes.
template <typename Scalar>
struct SpatialInertia
{
  Scalar m = Scalar(0);
  Vector3<Scalar> h = Vector3<Scalar>::Zero();
  Matrix3<Scalar> I = Matrix3<Scalar>::Zero();

  void add(const SpatialInertia& other)
  {
    m += other.m;
    h += other.h;
    I += other.I;
  }

  /// Lambda S for a twist S = (w, v): the momentum (n, f) with
  /// n = I w + h x v and f = m v - h x w, so that S_a^T Lambda S_b = w_a . n_b + v_a . f_b.
  Twist<Scalar> apply(const Twist<Scalar>& S) const
  {
    Twist<Scalar> momentum;
    momentum.w = I * S.w + cross(h, S.v);
    momentum.v = m * S.v - cross(h, S.w);
    return momentum;
  }
};

/// S^T (n, f) = w . n + v . f.
template <typename Scalar>
Scalar pairing(const Twist<Scalar>& S, const Twist<Scalar>& momentum)
{
  return dot3(S.w, momentum.w) + dot3(S.v, momentum.v);
}

/// Each segment's subtree inertia about the reference point.
template <typename Scalar>
std::vector<SpatialInertia<Scalar>> compositeInertias(const ArticulatedBody& body, const ArticulatedPose<Scalar>& pose)
{
  std::vector<SpatialInertia<Scalar>> composite(body.segments.size());
  for (std::size_t s = body.segments.size(); s-- > 0;)
  {
    const MassProperties& own = body.segments[s].mass_properties;
    SpatialInertia<Scalar>& c = composite[s];
    if (own.mass > 0.0)
    {
      const SegmentFrame<Scalar>& frame = pose.frames[s];
      const Scalar m(own.mass);
      const Vector3<Scalar> d = frame.R * own.com.template cast<Scalar>() + frame.p - pose.reference;
      SpatialInertia<Scalar> self;
      self.m = m;
      self.h = m * d;
      // R I R^T + m (|d|^2 I3 - d d^T), symmetric: the upper triangle, mirrored.
      const Matrix3<Scalar> RI = frame.R * castMatrix<Scalar>(own.inertia);
      const Scalar d2 = dot3(d, d);
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
        {
          self.I(i, j) = RI(i, 0) * frame.R(j, 0) + RI(i, 1) * frame.R(j, 1) + RI(i, 2) * frame.R(j, 2) -
                         m * d[i] * d[j];
          self.I(j, i) = self.I(i, j);
        }
      for (int i = 0; i < 3; ++i)
        self.I(i, i) += m * d2;
      c.add(self);
    }
    const int parent = body.segments[s].parent;
    if (parent >= 0)
      composite[static_cast<std::size_t>(parent)].add(c);
  }
  return composite;
}

/// The six twists of a floating root's coordinates.
template <typename Scalar>
std::array<Twist<Scalar>, 6> rootTwists(const ArticulatedPose<Scalar>& pose)
{
  std::array<Twist<Scalar>, 6> twists;
  for (int k = 0; k < 3; ++k)
  {
    twists[k].w = pose.root_T.col(k);
    twists[k].v.setZero();
    twists[k + 3].w.setZero();
    twists[k + 3].v = Vector3<Scalar>::Unit(k);
  }
  return twists;
}
}  // namespace detail

/// M(x), dof x dof, symmetric (see the header comment).
template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> articulatedMassMatrix(const ArticulatedBody& body,
                                                                             const ArticulatedPose<Scalar>& pose)
{
  const Eigen::Index dofs = static_cast<Eigen::Index>(body.dofs());
  Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> M =
      Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>::Zero(dofs, dofs);
  const std::vector<detail::SpatialInertia<Scalar>> composite = detail::compositeInertias(body, pose);
  std::array<Twist<Scalar>, 6> root;
  if (body.floating_root)
  {
    root = detail::rootTwists(pose);
    for (int l = 0; l < 6; ++l)
    {
      const Twist<Scalar> momentum = composite[0].apply(root[l]);
      for (int k = 0; k <= l; ++k)
        M(k, l) = M(l, k) = detail::pairing(root[k], momentum);
    }
  }
  for (std::size_t b = 0; b < body.segments.size(); ++b)
  {
    const Segment& deeper = body.segments[b];
    if (deeper.coordinate < 0)
      continue;
    const Twist<Scalar> momentum = composite[b].apply(pose.joint_twists[b]);
    const Scalar mb(deeper.multiplier);
    const Eigen::Index cb = deeper.coordinate;
    // Pairs (a, b) with a an ancestor of b or b itself: both move b's subtree.
    for (int a = static_cast<int>(b); a >= 0; a = body.segments[static_cast<std::size_t>(a)].parent)
    {
      const Segment& upper = body.segments[static_cast<std::size_t>(a)];
      if (upper.coordinate < 0)
        break;
      const Scalar value = Scalar(upper.multiplier) * mb * detail::pairing(pose.joint_twists[a], momentum);
      const Eigen::Index ca = upper.coordinate;
      M(ca, cb) += value;
      if (a != static_cast<int>(b))
        M(cb, ca) += value;
    }
    if (body.floating_root)
      for (Eigen::Index k = 0; k < 6; ++k)
      {
        const Scalar value = mb * detail::pairing(root[static_cast<std::size_t>(k)], momentum);
        M(k, cb) += value;
        M(cb, k) += value;
      }
  }
  return M;
}

/// M(x) at x (len = body.dofs()).
template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> articulatedMassMatrix(const ArticulatedBody& body,
                                                                             const Scalar* x)
{
  return articulatedMassMatrix(body, articulatedPose(body, x));
}

/// Position in the fixed frame of body vertex v at pose `pose`.
template <typename Scalar>
Vector3<Scalar> articulatedVertexPosition(const ArticulatedBody& body, const ArticulatedPose<Scalar>& pose,
                                          std::uint32_t v)
{
  const SegmentFrame<Scalar>& frame = pose.frames[body.segmentOfVertex(v)];
  return frame.R * body.vertices.col(v).template cast<Scalar>() + frame.p;
}

}  // namespace diff_rigid_body
