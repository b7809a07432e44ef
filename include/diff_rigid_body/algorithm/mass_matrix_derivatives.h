// dM/dx of a body, analytically: the derivative of the composite-rigid-body
// recursion (crba.h), in motion coordinates, then through the chart.
//
// Moving dof k carries everything it moves but the dofs of its own block
// after it (body_model.h): the unit motions, momenta and inertias change as
//   dS/dq_k = S_k x S,   dF/dq_k = S_k x* F,   dIc/dq_k = rate of Ic under S_k
// (spatial.h), and nothing above it changes. With H(c_a, c_b) built from
// S_a . Ic_seg(b) S_b for a an ancestor of b (or b), the cases are
//   a and b carried by k (or k):     0 (the pair moves rigidly; S . Y S is
//                                    frame-invariant)
//   a not carried, b carried or k:   S_a . (S_k x* F_b),   F_b = Ic_seg(b) S_b
//   b not carried, above k or in     S_a . (D_k S_b),      D_k the rate of Ic_seg(k) under S_k
//   k's block after k:
// ("not carried": strictly above k, or in k's block after it), and dH along
// nu_c sums multiplier_k dH/dq_k over the dofs k that nu_c drives (each term
// also carries m_a m_b). Dofs that are not on b's path or below it
// contribute 0. Work: O(dofs x depth^2). In x, with M = A^T H A
// (motion_coordinates.h) and dA_c = dA/dx_c (a free root's theta and psi):
//   dM/dx_c = A^T (dH along A e_c) A + dA_c^T H A + A^T H dA_c.
//
// Checked against the complex step of crba and against forward-mode AutoDiff
// (test_body_algorithms.cpp); a free object takes the closed form of
// free_body/mass_matrix.h in massMatrixDerivativesRowMajor.
#pragma once

#include "diff_rigid_body/algorithm/crba.h"

namespace diff_rigid_body
{
namespace detail
{
/// Adds value to dM/dx_c (c, r) and, for r != col, (col, r): the d x d
/// matrices of `dM` row-major, d^2 apart.
template <typename Scalar>
void addSymmetric(Scalar* dM, std::size_t d, int c, int row, int col, const Scalar& value, bool diagonal_pair)
{
  Scalar* matrix = dM + static_cast<std::size_t>(c) * d * d;
  matrix[static_cast<std::size_t>(row) * d + static_cast<std::size_t>(col)] += value;
  if (!diagonal_pair)
    matrix[static_cast<std::size_t>(col) * d + static_cast<std::size_t>(row)] += value;
}

/// S_a . G added to dH along dof k's coordinate, at (a, b) and (b, a).
template <typename Scalar>
void addPairTerm(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Scalar* dM, int k, int a, int b,
                 const Force<Scalar>& G)
{
  const Dof &dof_k = model.dofs[static_cast<std::size_t>(k)], &dof_a = model.dofs[static_cast<std::size_t>(a)],
            &dof_b = model.dofs[static_cast<std::size_t>(b)];
  const Scalar value = Scalar(dof_k.multiplier * dof_b.multiplier * dof_a.multiplier) *
                       spatial::power(ws.S[static_cast<std::size_t>(a)], G);
  addSymmetric(dM, model.coordinates, dof_k.coordinate, dof_a.coordinate, dof_b.coordinate, value, a == b);
}

/// Case "a not carried, b carried by k (or k)", for every dof b.
template <typename Scalar>
void addCarriedMomentumTerms(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Scalar* dM)
{
  const auto parent = [&](int k) { return model.dofs[static_cast<std::size_t>(k)].parent; };
  for (std::size_t b = 0; b < model.dofs.size(); ++b)
  {
    const int deeper = static_cast<int>(b);
    for (int k = deeper; k >= 0; k = parent(k))
    {
      const int block_last = model.dofs[static_cast<std::size_t>(k)].block_last;
      if (k != deeper && block_last >= deeper)
        continue;  // b in k's block: not carried
      const Force<Scalar> G = spatial::crossForce(ws.S[static_cast<std::size_t>(k)], ws.momentum[b]);
      for (int a = parent(k); a >= 0; a = parent(a))
        addPairTerm(model, ws, dM, k, a, deeper, G);
      if (k != deeper)
        for (int a = k + 1; a <= block_last; ++a)
          addPairTerm(model, ws, dM, k, a, deeper, G);
    }
  }
}

/// Case "b not carried: above k, or in k's block after k", for every dof k.
template <typename Scalar>
void addCarriedInertiaTerms(const BodyModel& model, BodyWorkspace<Scalar>& ws, Scalar* dM)
{
  const auto parent = [&](int k) { return model.dofs[static_cast<std::size_t>(k)].parent; };
  for (std::size_t k = 0; k < model.dofs.size(); ++k)
  {
    const Dof& dof_k = model.dofs[k];
    const int moving = static_cast<int>(k);
    if (dof_k.parent < 0 && dof_k.block_last == moving)
      continue;
    const Inertia<Scalar>& D = ws.carried_rate[k] =
        spatial::carriedInertiaRate(ws.S[k], ws.composite[static_cast<std::size_t>(dof_k.segment)]);
    const auto addColumn = [&](int b) {
      const Force<Scalar> P = spatial::momentum(D, ws.S[static_cast<std::size_t>(b)]);
      for (int a = b; a >= 0; a = parent(a))
        addPairTerm(model, ws, dM, moving, a, b, P);
    };
    for (int b = dof_k.parent; b >= 0; b = parent(b))
      addColumn(b);
    for (int b = moving + 1; b <= dof_k.block_last; ++b)
      addColumn(b);
  }
}

/// dH along nu (d matrices at dM) turned into dM/dx in place, for a free
/// root (see the header comment), with H and the chart in ws.
template <typename Scalar>
void massMatrixDerivativesToCoordinates(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Scalar* dM)
{
  using RowMajor = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  const Matrix3<Scalar>& T = ws.chart.T;
  for (Eigen::Index e = 0; e < d * d; ++e)  // dH along A e_c = sum_k T(k, c) dH along nu_k
  {
    const Vector3<Scalar> along(dM[e], dM[d * d + e], dM[2 * d * d + e]);
    for (int c = 0; c < 3; ++c)
      dM[c * d * d + e] = T(0, c) * along[0] + T(1, c) * along[1] + T(2, c) * along[2];
  }
  for (Eigen::Index c = 0; c < d; ++c)
  {
    Eigen::Map<RowMajor> D(dM + c * d * d, d, d);
    symmetricToCoordinates(model, ws, D);
  }
  for (int c = THETA; c <= PSI; ++c)  // + X + X^T, X = A^T H dA_c (its first three columns)
  {
    const Matrix3<Scalar> dT = ws.chart.derivative(c);
    const Matrix3<Scalar> top = T.transpose() * (ws.H.template topLeftCorner<3, 3>() * dT);
    Eigen::Map<RowMajor> D(dM + c * d * d, d, d);
    for (Eigen::Index i = 0; i < d; ++i)
    {
      const Eigen::Matrix<Scalar, 1, 3> y =
          i < 3 ? Eigen::Matrix<Scalar, 1, 3>(top.row(i)) :
                  Eigen::Matrix<Scalar, 1, 3>(ws.H.row(i).template head<3>() * dT);
      for (int k = 0; k < 3; ++k)
      {
        D(i, k) += y[k];
        D(k, i) += y[k];
      }
    }
  }
}
}  // namespace detail

/// dM/dx_j, j = 0..d-1, into dM (d^3 values: matrix j row-major at j d^2)
/// from the kinematics, composite inertias and H in ws (crba first); see
/// the header comment.
template <typename Scalar>
void massMatrixDerivativesFromCrba(const BodyModel& model, BodyWorkspace<Scalar>& ws, Scalar* dM)
{
  const std::size_t d = model.coordinates;
  std::fill(dM, dM + d * d * d, Scalar(0));
  detail::addCarriedMomentumTerms(model, ws, dM);
  detail::addCarriedInertiaTerms(model, ws, dM);
  if (model.hasFreeRoot())
    detail::massMatrixDerivativesToCoordinates(model, ws, dM);
}

/// dM/dx at x into dM (d^3 values): kinematics, CRBA, then the derivatives.
template <typename Scalar>
void massMatrixDerivatives(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x, Scalar* dM)
{
  crba(model, ws, x);
  massMatrixDerivativesFromCrba(model, ws, dM);
}

/// The node's dM/dx at x (d^3 values, dM/dx_j row-major at j d^2): a free
/// object by the closed form (free_body/mass_matrix.h), any other body by
/// massMatrixDerivativesFromCrba, after crba at x unless `crba_done` (ws
/// holds it already: massMatrices of x alone just ran).
void massMatrixDerivativesRowMajor(const BodyModel& model, BodyWorkspace<double>& ws, const double* x, double* dM,
                                   bool crba_done = false);

extern template void massMatrixDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*, double*);

}  // namespace diff_rigid_body
