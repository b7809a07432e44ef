// Independent kinematics oracles (Eigen only; of the library, only its type
// aliases), shared by the unit tests, the rostests and (possibly) the
// benchmarks.
//
// Everything here is written from docs/derivation.md, NOT from the headers
// under test: rotations are products of elementary rotations, dR is the long
// form (Rz Ry Rx' etc.), T is assembled from the definition of the rotation
// axes, M is T^T R I_b R^T T, and J is also given as [-[R p0]_x T, I3]. The
// kernels use the closed-form entries, cross products, A = R^T T and
// A^T I_b A instead, so an agreement between the two is evidence, not a
// tautology.
//
// q = (phi, theta, psi [rad], tx, ty, tz [m]); R = Rz(psi) Ry(theta) Rx(phi).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/types.h"  // Eigen aliases only: no library code

namespace drb_test
{
using diff_rigid_body::Matrix3;
using diff_rigid_body::Matrix36;
using diff_rigid_body::Matrix6;
using diff_rigid_body::Vector3;
using diff_rigid_body::Vector6;

// ---------------------------------------------------------------------------
// Elementary rotations and their derivatives (right-handed, active).

/// The rotation by `a` about axis k (0 = x, 1 = y, 2 = z), or its entry-wise
/// derivative d/da. In the plane of the next two axes in cyclic order,
/// (i, j) = (k + 1, k + 2) mod 3 (so y, z for x; z, x for y; x, y for z), it
/// is [c -s; s c], with derivative [-s -c; c -s]; on axis k it is 1 (0).
template <typename S>
Matrix3<S> elementaryRotation(int k, const S& a, bool derivative)
{
  using std::cos;
  using std::sin;
  const S c = cos(a), s = sin(a);
  Matrix3<S> m;
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col)
      m(r, col) = S(0);
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  m(k, k) = derivative ? S(0) : S(1);
  m(i, i) = derivative ? S(-s) : c;
  m(i, j) = derivative ? S(-c) : S(-s);
  m(j, i) = derivative ? c : s;
  m(j, j) = derivative ? S(-s) : c;
  return m;
}

constexpr int kX = 0, kY = 1, kZ = 2;

template <typename S>
Matrix3<S> rot(int k, const S& a)
{
  return elementaryRotation(k, a, false);
}

template <typename S>
Matrix3<S> rotPrime(int k, const S& a)
{
  return elementaryRotation(k, a, true);
}

// ---------------------------------------------------------------------------
// Reference kinematics (docs/derivation.md, "Coordinates and frames",
// "Angular velocity"), q = (phi, theta, psi, tx, ty, tz).

/// R = Rz(psi) Ry(theta) Rx(phi), as a product of elementary rotations.
template <typename S>
Matrix3<S> refRotation(const S& phi, const S& theta, const S& psi)
{
  return rot(kZ, psi) * rot(kY, theta) * rot(kX, phi);
}

/// Long form: dR/dphi = Rz Ry Rx', dR/dtheta = Rz Ry' Rx, dR/dpsi = Rz' Ry Rx.
template <typename S>
std::array<Matrix3<S>, 3> refRotationDerivatives(const S& phi, const S& theta, const S& psi)
{
  return { rot(kZ, psi) * rot(kY, theta) * rotPrime(kX, phi), rot(kZ, psi) * rotPrime(kY, theta) * rot(kX, phi),
           rotPrime(kZ, psi) * rot(kY, theta) * rot(kX, phi) };
}

/// T from the axis definition: omega = phidot e_X'' + thetadot e_Y' + psidot e_Z.
/// In world coordinates e_Z = (0,0,1), e_Y' = Rz(psi) e_y and
/// e_X'' = Rz(psi) Ry(theta) e_x (Rx(phi) leaves e_x fixed).
template <typename S>
Matrix3<S> refAngularVelocityMatrix(const S& phi, const S& theta, const S& psi)
{
  (void)phi;
  const Vector3<S> ex(S(1), S(0), S(0)), ey(S(0), S(1), S(0)), ez(S(0), S(0), S(1));
  Matrix3<S> T;
  T.col(0) = rot(kZ, psi) * (rot(kY, theta) * ex);
  T.col(1) = rot(kZ, psi) * ey;
  T.col(2) = ez;
  return T;
}

/// [v]_x, the cross-product matrix.
template <typename S>
Matrix3<S> skew(const Vector3<S>& v)
{
  Matrix3<S> m;
  m << S(0), -v[2], v[1],  //
      v[2], S(0), -v[0],   //
      -v[1], v[0], S(0);
  return m;
}

/// Inverse of skew, taking the antisymmetric part.
template <typename S>
Vector3<S> vee(const Matrix3<S>& m)
{
  return Vector3<S>((m(2, 1) - m(1, 2)) / S(2), (m(0, 2) - m(2, 0)) / S(2), (m(1, 0) - m(0, 1)) / S(2));
}

/// J = [dR/dphi p0, dR/dtheta p0, dR/dpsi p0 | I3], long form.
template <typename S>
Matrix36<S> refJacobian(const Vector6<S>& q, const Vector3<S>& p0)
{
  const auto dR = refRotationDerivatives(q[0], q[1], q[2]);
  Matrix36<S> J = Matrix36<S>::Zero();
  for (int k = 0; k < 3; ++k)
    J.col(k) = dR[k] * p0;
  J.template rightCols<3>().setIdentity();
  return J;
}

/// p = R p0 + t with the product-form R.
template <typename S>
Vector3<S> refPosition(const Vector6<S>& q, const Vector3<S>& p0)
{
  return refRotation(q[0], q[1], q[2]) * p0 + q.template tail<3>();
}

/// M = blockdiag(T^T I' T, m I3), I' = R I_b R^T: the world-frame form
/// (docs/derivation.md, "Mass matrix"; the seed's eq. (22) prints I3 for m I3).
template <typename S>
Matrix6<S> refMassMatrix(const Vector6<S>& q, const S& mass, const Matrix3<S>& inertia_body)
{
  const Matrix3<S> R = refRotation(q[0], q[1], q[2]);
  const Matrix3<S> T = refAngularVelocityMatrix(q[0], q[1], q[2]);
  const Matrix3<S> I_world = R * inertia_body * R.transpose();
  Matrix6<S> M = Matrix6<S>::Zero();
  M.template topLeftCorner<3, 3>() = T.transpose() * I_world * T;
  for (int i = 3; i < 6; ++i)
    M(i, i) = mass;
  return M;
}

/// Inertia about the origin of point masses (docs/derivation.md, "Inertia", particles):
/// I = sum m_i (p_i^T p_i I3 - p_i p_i^T).
template <typename S>
Matrix3<S> particleInertia(const std::vector<Vector3<S>>& points, const std::vector<S>& masses)
{
  Matrix3<S> I = Matrix3<S>::Zero();
  for (std::size_t i = 0; i < points.size(); ++i)
    I += masses[i] * (points[i].squaredNorm() * Matrix3<S>::Identity() - points[i] * points[i].transpose());
  return I;
}
/// J = dp/dq = [-[R p0]_x T, I3] (omega x (R p0) with omega = T rdot): the
/// angular-velocity form, a second route to refJacobian's long form.
template <typename S>
Matrix36<S> refJacobianFromAngularVelocity(const Vector6<S>& q, const Vector3<S>& p0)
{
  Matrix36<S> J;
  J.template leftCols<3>() =
      -skew(Vector3<S>(refRotation(q[0], q[1], q[2]) * p0)) * refAngularVelocityMatrix(q[0], q[1], q[2]);
  J.template rightCols<3>().setIdentity();
  return J;
}

/// dL/dq = sum_i J_i^T g_i = (T^T sum_i (R p0_i) x g_i, sum_i g_i), for
/// dL/dp_i = g_i.
template <typename S>
Vector6<S> refBackprop(const Vector6<S>& q, const std::vector<Vector3<S>>& p0, const std::vector<Vector3<S>>& g)
{
  const Matrix3<S> R = refRotation(q[0], q[1], q[2]);
  Vector3<S> moment = Vector3<S>::Zero(), force = Vector3<S>::Zero();
  for (std::size_t i = 0; i < p0.size(); ++i)
  {
    moment += Vector3<S>(R * p0[i]).cross(g[i]);
    force += g[i];
  }
  Vector6<S> out;
  out.template head<3>() = refAngularVelocityMatrix(q[0], q[1], q[2]).transpose() * moment;
  out.template tail<3>() = force;
  return out;
}

}  // namespace drb_test
