// H = L^T D L along the body's tree (Featherstone 2008, section 6.3, "LTDL"),
// for forward dynamics (forward_dynamics.h). H is the mass matrix in motion
// coordinates (crba.h): well conditioned where M = A^T H A is not (near a
// free root's gimbal lock), so forward dynamics factors H, never M.
//
// In dof order H has the tree's sparsity: H(i, j) != 0 only when one of the
// dofs i, j is an ancestor of the other. Eliminating from the leaves up,
// row k only ever updates the rows of its ancestors, so no fill-in occurs:
//   for k = last..0, for i = each ancestor of k:
//     a = M(k, i) / M(k, k);  M(i, j) -= a M(k, j) for j = i and its ancestors;  L(k, i) = a
// and D = diag of what is left. Work O(dofs x depth^2); a chain (depth = d)
// is the dense LDL^T, which serves bodies with mimic joints (several dofs per
// coordinate). BodyModel::factor_coordinate and factor_parent give the order.
//
// H is positive semidefinite; a pivot D_k <= d eps max_i H_ii (rounding of
// a zero) means H is singular: a coordinate that moves no mass (or a free
// root's rotation that moves no inertia). The factorization then reports
// the row's coordinate.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include "diff_rigid_body/multibody/body_workspace.h"

namespace diff_rigid_body
{
namespace detail
{
/// |value| in double for the singularity test: the real part of a complex
/// step (its imaginary part carries derivatives, not size).
template <typename Scalar>
double pivotMagnitude(const Scalar& value)
{
  using std::abs;
  return static_cast<double>(abs(value));
}
template <typename Real>
double pivotMagnitude(const std::complex<Real>& value)
{
  return std::abs(static_cast<double>(value.real()));
}
}  // namespace detail

/// Factors ws.H into ws.factor (rows and columns in factorization order).
/// Returns -1, or the coordinate of the first pivot found singular.
template <typename Scalar>
int factorMassMatrix(const BodyModel& model, BodyWorkspace<Scalar>& ws)
{
  const int d = static_cast<int>(model.coordinates);
  auto& H = ws.factor;
  for (int r = 0; r < d; ++r)
    for (int c = 0; c < d; ++c)
      H(r, c) = ws.H(model.factor_coordinate[static_cast<std::size_t>(r)], model.factor_coordinate[static_cast<std::size_t>(c)]);
  double largest = 0.0;
  for (int k = 0; k < d; ++k)
    largest = std::max(largest, detail::pivotMagnitude(H(k, k)));
  const double tolerance = d * std::numeric_limits<double>::epsilon() * largest;
  int singular = -1;
  for (int k = d - 1; k >= 0; --k)
  {
    if (!(detail::pivotMagnitude(H(k, k)) > tolerance) && singular < 0)
      singular = model.factor_coordinate[static_cast<std::size_t>(k)];
    for (int i = model.factor_parent[static_cast<std::size_t>(k)]; i >= 0; i = model.factor_parent[static_cast<std::size_t>(i)])
    {
      const Scalar a = H(k, i) / H(k, k);
      for (int j = i; j >= 0; j = model.factor_parent[static_cast<std::size_t>(j)])
        H(i, j) -= a * H(k, j);
      H(k, i) = a;
    }
  }
  return singular;
}

/// Solves H y = b for b given in nu order (d values at `b`), in place, with
/// the factorization in ws. ws.solution is used as scratch.
template <typename Scalar>
void solveMassMatrix(const BodyModel& model, BodyWorkspace<Scalar>& ws, Scalar* b)
{
  const int d = static_cast<int>(model.coordinates);
  const auto& H = ws.factor;
  auto& y = ws.solution;
  const auto parent = [&](int k) { return model.factor_parent[static_cast<std::size_t>(k)]; };
  for (int k = 0; k < d; ++k)
    y[k] = b[model.factor_coordinate[static_cast<std::size_t>(k)]];
  for (int k = d - 1; k >= 0; --k)  // L^T z = b
    for (int j = parent(k); j >= 0; j = parent(j))
      y[j] -= H(k, j) * y[k];
  for (int k = 0; k < d; ++k)  // D w = z
    y[k] /= H(k, k);
  for (int k = 0; k < d; ++k)  // L y = w
    for (int j = parent(k); j >= 0; j = parent(j))
      y[k] -= H(k, j) * y[j];
  for (int k = 0; k < d; ++k)
    b[model.factor_coordinate[static_cast<std::size_t>(k)]] = y[k];
}

/// Solves H Y = B in place for every column of B (d x n, nu order in rows),
/// with the factorization in ws: the same walks as solveMassMatrix, each
/// step a whole row of B at once (ws.factor_rows is the scratch, factor
/// rows as its columns, so every update is contiguous). n <= d.
template <typename Scalar>
void solveMassMatrixColumns(const BodyModel& model, BodyWorkspace<Scalar>& ws,
                            typename BodyWorkspace<Scalar>::MatrixX& B)
{
  const int d = static_cast<int>(model.coordinates);
  const auto& H = ws.factor;
  // Column k = row k of the system in factorization order, in ws.factor_rows'
  // storage (nothing is allocated).
  Eigen::Map<typename BodyWorkspace<Scalar>::MatrixX> Y(ws.factor_rows.data(), B.cols(), d);
  const auto parent = [&](int k) { return model.factor_parent[static_cast<std::size_t>(k)]; };
  const auto coordinate = [&](int k) { return static_cast<Eigen::Index>(model.factor_coordinate[static_cast<std::size_t>(k)]); };
  for (int k = 0; k < d; ++k)
    Y.col(k) = B.row(coordinate(k)).transpose();
  const Eigen::Index n = Y.rows();
  Scalar* const rows = Y.data();
  const auto axpy = [&](int target, const Scalar& a, int source) {  // row target -= a row source
    Scalar* __restrict__ y = rows + target * n;
    const Scalar* __restrict__ x = rows + source * n;
    for (Eigen::Index i = 0; i < n; ++i)
      y[i] -= a * x[i];
  };
  for (int k = d - 1; k >= 0; --k)  // L^T Z = B
    for (int j = parent(k); j >= 0; j = parent(j))
      axpy(j, H(k, j), k);
  for (int k = 0; k < d; ++k)  // D W = Z
  {
    const Scalar pivot = H(k, k);
    Scalar* y = rows + k * n;
    for (Eigen::Index i = 0; i < n; ++i)
      y[i] /= pivot;
  }
  for (int k = 0; k < d; ++k)  // L Y = W
    for (int j = parent(k); j >= 0; j = parent(j))
      axpy(k, H(k, j), j);
  for (int k = 0; k < d; ++k)
    B.row(coordinate(k)) = Y.col(k).transpose();
}

}  // namespace diff_rigid_body
