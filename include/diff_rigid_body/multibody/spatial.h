// Spatial algebra in the fixed frame about one reference point r (Plucker
// coordinates taken at r, fixed-frame axes), templated on the scalar.
//
//   Motion  (w, v): angular velocity w [rad/s], and the velocity v [m/s] of
//           the body point that is at r; a unit motion (a dof's twist) has
//           the same form per unit of its coordinate.
//   Force   (n, f): moment n about r [N m], force f [N].
//   Inertia (m, h, I): mass m [kg], first moment h = m (c - r) [kg m] of a
//           COM at c, rotational inertia I about r in fixed axes [kg m^2],
//           I = I_c + m (|d|^2 I3 - d d^T), d = c - r.
//
//   power             S . F = w . n + v . f
//   momentum          Y S   = (I w + h x v, m v - h x w)
//   motion cross      a x S  = (a.w x S.w, a.w x S.v + a.v x S.w)
//   force cross       a x* F = (a.w x F.n + a.v x F.f, a.w x F.f)
// with (a x S) . F = -S . (a x* F). A body whose points move with the motion
// a carries its motions, forces and inertia along: dS/dt = a x S, and
//   dY/dt = (0, m a.v + a.w x h, [w]I - I[w] + 2 (h . v) I3 - v h^T - h v^T),
// which is again of inertia form (Featherstone, "Rigid Body Dynamics
// Algorithms", 2008, ch. 2; the last line is d/dt of sum m_i (|x_i|^2 I3 - x_i x_i^T)
// with x_i' = v + w x x_i).
//
// Products are written out component by component: Eigen's dot and cross
// conjugate complex scalars, which would break complex-step derivatives.
#pragma once

#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
template <typename Scalar>
struct Motion
{
  Vector3<Scalar> w = Vector3<Scalar>::Zero();
  Vector3<Scalar> v = Vector3<Scalar>::Zero();
};

template <typename Scalar>
struct Force
{
  Vector3<Scalar> n = Vector3<Scalar>::Zero();
  Vector3<Scalar> f = Vector3<Scalar>::Zero();
};

template <typename Scalar>
struct Inertia
{
  Scalar m = Scalar(0);
  Vector3<Scalar> h = Vector3<Scalar>::Zero();
  Matrix3<Scalar> I = Matrix3<Scalar>::Zero();
};

namespace spatial
{
/// a . b without conjugation.
template <typename Scalar>
inline Scalar dot(const Vector3<Scalar>& a, const Vector3<Scalar>& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// a x b without conjugation.
template <typename Scalar>
inline Vector3<Scalar> cross(const Vector3<Scalar>& a, const Vector3<Scalar>& b)
{
  return Vector3<Scalar>(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}

/// S . F = w . n + v . f.
template <typename Scalar>
inline Scalar power(const Motion<Scalar>& S, const Force<Scalar>& F)
{
  return dot(S.w, F.n) + dot(S.v, F.f);
}

/// Y S = (I w + h x v, m v - h x w).
template <typename Scalar>
inline Force<Scalar> momentum(const Inertia<Scalar>& Y, const Motion<Scalar>& S)
{
  Force<Scalar> F;
  F.n = Y.I * S.w + cross(Y.h, S.v);
  F.f = Y.m * S.v - cross(Y.h, S.w);
  return F;
}

/// a x S = (a.w x S.w, a.w x S.v + a.v x S.w).
template <typename Scalar>
inline Motion<Scalar> crossMotion(const Motion<Scalar>& a, const Motion<Scalar>& S)
{
  Motion<Scalar> out;
  out.w = cross(a.w, S.w);
  out.v = cross(a.w, S.v) + cross(a.v, S.w);
  return out;
}

/// a x* F = (a.w x F.n + a.v x F.f, a.w x F.f).
template <typename Scalar>
inline Force<Scalar> crossForce(const Motion<Scalar>& a, const Force<Scalar>& F)
{
  Force<Scalar> out;
  out.n = cross(a.w, F.n) + cross(a.v, F.f);
  out.f = cross(a.w, F.f);
  return out;
}

template <typename Scalar>
inline void add(Inertia<Scalar>& Y, const Inertia<Scalar>& other)
{
  Y.m += other.m;
  Y.h += other.h;
  Y.I += other.I;
}

/// The inertia about r of a body of mass m with COM c and inertia about the
/// COM in fixed axes R I_c R^T, from its frame (R, p) and its COM c0 and
/// inertia I0 in that frame: c = R c0 + p, d = c - r,
///   I = R I0 R^T + m (|d|^2 I3 - d d^T)   (symmetric: the upper triangle, mirrored).
template <typename Scalar>
inline Inertia<Scalar> inertiaAbout(const Vector3<Scalar>& r, const Matrix3<Scalar>& R, const Vector3<Scalar>& p,
                             double mass, const Eigen::Vector3d& c0, const Eigen::Matrix3d& I0)
{
  Inertia<Scalar> Y;
  Y.m = Scalar(mass);
  const Vector3<Scalar> d = R * c0.template cast<Scalar>() + p - r;
  Y.h = Y.m * d;
  const Matrix3<Scalar> RI = R * I0.template cast<Scalar>();
  const Scalar d2 = dot(d, d);
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
    {
      Y.I(i, j) = RI(i, 0) * R(j, 0) + RI(i, 1) * R(j, 1) + RI(i, 2) * R(j, 2) - Y.m * d[i] * d[j];
      Y.I(j, i) = Y.I(i, j);
    }
  for (int i = 0; i < 3; ++i)
    Y.I(i, i) += Y.m * d2;
  return Y;
}

/// dY/dt of an inertia carried by the motion a (see the header comment);
/// its m is 0.
template <typename Scalar>
Inertia<Scalar> carriedInertiaRate(const Motion<Scalar>& a, const Inertia<Scalar>& Y)
{
  Inertia<Scalar> D;
  D.h = Y.m * a.v + cross(a.w, Y.h);
  Matrix3<Scalar> X;  // [w] I, column by column
  for (int j = 0; j < 3; ++j)
    X.col(j) = cross(a.w, Vector3<Scalar>(Y.I.col(j)));
  const Scalar hv = Scalar(2) * dot(Y.h, a.v);
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
    {
      D.I(i, j) = X(i, j) + X(j, i) - a.v[i] * Y.h[j] - Y.h[i] * a.v[j];
      D.I(j, i) = D.I(i, j);
    }
  for (int i = 0; i < 3; ++i)
    D.I(i, i) += hv;
  return D;
}

}  // namespace spatial
}  // namespace diff_rigid_body
