// The edge between a body's coordinates x and the motion coordinates nu the
// algorithms run in (body_model.h, free_root_chart.h):
//   nu = A x',   nu' = A x'' + Q,   tau_x = A^T tau_nu,   M = A^T H A,
// with A = blockdiag(T, I3, I) and Q = (T' x_r', 0, ...) for a free root,
// and A = I, Q = 0 for a fixed base (then every function here passes its
// input through untouched). Inverse maps (forward dynamics):
//   tau_nu = A^-T tau_x,   x'' = A^-1 (nu' - Q).
// A free root's rotation coordinates are x[0..2] and nu[0..2], so A acts on
// the first three rows or columns. Each function needs the kinematics at x
// (ws.chart) and allocates nothing.
#pragma once

#include "diff_rigid_body/multibody/body_workspace.h"

namespace diff_rigid_body
{
/// nu = A x' (ws.nu for a free root, else xd itself; null stays null).
template <typename Scalar>
const Scalar* motionRates(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* xd)
{
  if (!xd || !model.hasFreeRoot())
    return xd;
  ws.nu = Eigen::Map<const typename BodyWorkspace<Scalar>::VectorX>(xd, ws.nu.size());
  ws.nu.template head<3>() = ws.chart.T * Eigen::Map<const Vector3<Scalar>>(xd);
  return ws.nu.data();
}

/// nu' = A x'' + Q (ws.nu_dot for a free root, else xdd itself); null xd
/// or xdd mean zeros, and null when both are.
template <typename Scalar>
const Scalar* motionAccelerations(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* xd,
                                  const Scalar* xdd)
{
  if (!model.hasFreeRoot() || (!xd && !xdd))
    return xdd;
  if (xdd)
    ws.nu_dot = Eigen::Map<const typename BodyWorkspace<Scalar>::VectorX>(xdd, ws.nu_dot.size());
  else
    ws.nu_dot.setZero();
  auto rotation = ws.nu_dot.template head<3>();
  if (xdd)
    rotation = ws.chart.T * Eigen::Map<const Vector3<Scalar>>(xdd);
  if (xd)
    rotation += ws.chart.velocityProduct(xd);
  return ws.nu_dot.data();
}

/// tau_x = A^T tau_nu, in place (d values).
template <typename Scalar>
void forceToCoordinates(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Scalar* tau)
{
  if (!model.hasFreeRoot())
    return;
  Eigen::Map<Vector3<Scalar>> rotation(tau);
  rotation = (ws.chart.T.transpose() * rotation).eval();
}

/// m's first three columns times `right` (3 x 3): A with right = T, A^-T
/// with T^-T (free root only). Row by row, in fixed-size pieces: nothing is
/// allocated.
template <typename Scalar, typename Matrix>
void mapRotationColumns(const BodyModel& model, const Matrix3<Scalar>& right, Matrix& m)
{
  if (!model.hasFreeRoot())
    return;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
  {
    const Eigen::Matrix<Scalar, 1, 3> row(m(i, 0), m(i, 1), m(i, 2));
    for (int c = 0; c < 3; ++c)
      m(i, c) = row[0] * right(0, c) + row[1] * right(1, c) + row[2] * right(2, c);
  }
}

/// m times A from the right: its first three columns (directions in nu)
/// turned into the rotation coordinates' (free root only).
template <typename Scalar, typename Matrix>
void columnsToCoordinates(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Matrix& m)
{
  mapRotationColumns(model, ws.chart.T, m);
}

/// m (rows in nu) times `left` (3 x 3) on its first three rows: A^T with
/// left = T^T, A^-1 with T^-1, A^-T with T^-T (free root only).
template <typename Scalar, typename Matrix>
void mapRotationRows(const BodyModel& model, const Matrix3<Scalar>& left, Matrix& m)
{
  if (!model.hasFreeRoot())
    return;
  for (Eigen::Index j = 0; j < m.cols(); ++j)
  {
    const Vector3<Scalar> column(m(0, j), m(1, j), m(2, j));
    for (int r = 0; r < 3; ++r)
      m(r, j) = left(r, 0) * column[0] + left(r, 1) * column[1] + left(r, 2) * column[2];
  }
}

/// m times A^T from the left: its first three rows turned into the rotation
/// coordinates' (free root only).
template <typename Scalar, typename Matrix>
void rowsToCoordinates(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Matrix& m)
{
  mapRotationRows(model, Matrix3<Scalar>(ws.chart.T.transpose()), m);
}

/// A^T m A in place for a symmetric d x d `m` (free root only), exactly
/// symmetric again: the mixed block once, mirrored; the rotation block's
/// upper triangle, mirrored.
template <typename Scalar, typename Matrix>
void symmetricToCoordinates(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Matrix& m)
{
  if (!model.hasFreeRoot())
    return;
  const Matrix3<Scalar>& T = ws.chart.T;
  for (Eigen::Index j = 3; j < m.cols(); ++j)
  {
    const Vector3<Scalar> column(m(0, j), m(1, j), m(2, j));
    for (int r = 0; r < 3; ++r)
      m(j, r) = m(r, j) = T(0, r) * column[0] + T(1, r) * column[1] + T(2, r) * column[2];
  }
  Matrix3<Scalar> block;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      block(r, c) = m(r, c);
  const Matrix3<Scalar> W = T.transpose() * (block * T);
  for (int r = 0; r < 3; ++r)
    for (int c = r; c < 3; ++c)
      m(c, r) = m(r, c) = W(r, c);
}

/// M = A^T H A into ws.M from ws.H (exactly symmetric).
template <typename Scalar>
void massMatrixToCoordinates(const BodyModel& model, BodyWorkspace<Scalar>& ws)
{
  ws.M = ws.H;
  symmetricToCoordinates(model, ws, ws.M);
}

/// H's first three columns (a free root's w) into ws.rotation_columns from
/// the composite inertias in ws: H(c_i, k) = sum over the dofs i on c_i of
/// m_i S_i . Ic_seg(i) (e_k, 0).
template <typename Scalar>
void rotationColumnsOfH(const BodyModel& model, BodyWorkspace<Scalar>& ws)
{
  ws.rotation_columns.setZero();
  for (std::size_t i = 0; i < model.dofs.size(); ++i)
  {
    const Dof& dof = model.dofs[i];
    const Inertia<Scalar>& Ic = ws.composite[static_cast<std::size_t>(dof.segment)];
    const Motion<Scalar>& S = ws.S[i];
    for (int k = 0; k < 3; ++k)
    {
      Motion<Scalar> rotation;
      rotation.w[k] = Scalar(1);
      ws.rotation_columns(dof.coordinate, k) += Scalar(dof.multiplier) * spatial::power(S, spatial::momentum(Ic, rotation));
    }
  }
}

}  // namespace diff_rigid_body
