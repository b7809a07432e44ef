// dM/dx of a body, analytically: the derivative of the composite-rigid-body
// recursion (crba.h). Moving dof k carries everything below it: the unit
// motions, momenta and inertias of its subtree change as
//   dS/dq_k = S_k x S,   dF/dq_k = S_k x* F,   dIc/dq_k = rate of Ic under S_k
// (spatial.h), and nothing above it changes. With M(c_a, c_b) built from
// S_a . Ic_seg(b) S_b for a an ancestor of b (or b), the three cases are
//   k an ancestor of a, or a:        0 (the pair moves rigidly; S . Y S is
//                                    frame-invariant)
//   a strictly above k, k above b    S_a . (S_k x* F_b),   F_b = Ic_seg(b) S_b
//   (or k = b):
//   b strictly above k:              S_a . (D_k S_b),      D_k the rate of Ic_seg(k) under S_k
// and dM/dx_c sums multiplier_k dM/dq_k over the dofs k that x_c drives
// (each term also carries m_a m_b). Dofs that are not on b's path or below
// it contribute 0. A free root's six dofs are the chain tx, ty, tz, psi,
// theta, phi, so the Euler-angle terms dT/dphi, dT/dtheta come out of the
// same rule (dS_phi/dpsi = S_psi x S_phi, ...). Work: O(dofs x depth^2).
//
// Checked against the complex step of crba and against forward-mode AutoDiff
// (test_body_algorithms.cpp); a free object takes the closed form of
// free_body/mass_matrix.h (math.md) in massMatrixDerivativesRowMajor.
#pragma once

#include "diff_rigid_body/crba.h"

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

/// Case "a strictly above k, k above b or k = b", for every dof b.
template <typename Scalar>
void addCarriedMomentumTerms(const BodyModel& model, const BodyWorkspace<Scalar>& ws, Scalar* dM)
{
  const std::size_t d = model.coordinates;
  for (std::size_t b = 0; b < model.dofs.size(); ++b)
  {
    const Dof& dof_b = model.dofs[b];
    for (int k = static_cast<int>(b); k >= 0; k = model.dofs[static_cast<std::size_t>(k)].parent)
    {
      const Dof& dof_k = model.dofs[static_cast<std::size_t>(k)];
      if (dof_k.parent < 0)
        break;
      const Force<Scalar> G = spatial::crossForce(ws.S[static_cast<std::size_t>(k)], ws.momentum[b]);
      const double mkb = dof_k.multiplier * dof_b.multiplier;
      for (int a = dof_k.parent; a >= 0; a = model.dofs[static_cast<std::size_t>(a)].parent)
      {
        const Dof& dof_a = model.dofs[static_cast<std::size_t>(a)];
        const Scalar value = Scalar(mkb * dof_a.multiplier) * spatial::power(ws.S[static_cast<std::size_t>(a)], G);
        addSymmetric(dM, d, dof_k.coordinate, dof_a.coordinate, dof_b.coordinate, value, false);
      }
    }
  }
}

/// Case "b strictly above k", for every dof k.
template <typename Scalar>
void addCarriedInertiaTerms(const BodyModel& model, BodyWorkspace<Scalar>& ws, Scalar* dM)
{
  const std::size_t d = model.coordinates;
  for (std::size_t k = 0; k < model.dofs.size(); ++k)
  {
    const Dof& dof_k = model.dofs[k];
    if (dof_k.parent < 0)
      continue;
    const Inertia<Scalar>& D = ws.carried_rate[k] =
        spatial::carriedInertiaRate(ws.S[k], ws.composite[static_cast<std::size_t>(dof_k.segment)]);
    for (int b = dof_k.parent; b >= 0; b = model.dofs[static_cast<std::size_t>(b)].parent)
    {
      const Dof& dof_b = model.dofs[static_cast<std::size_t>(b)];
      const Force<Scalar> P = spatial::momentum(D, ws.S[static_cast<std::size_t>(b)]);
      const double mkb = dof_k.multiplier * dof_b.multiplier;
      for (int a = b; a >= 0; a = model.dofs[static_cast<std::size_t>(a)].parent)
      {
        const Dof& dof_a = model.dofs[static_cast<std::size_t>(a)];
        const Scalar value = Scalar(mkb * dof_a.multiplier) * spatial::power(ws.S[static_cast<std::size_t>(a)], P);
        addSymmetric(dM, d, dof_k.coordinate, dof_a.coordinate, dof_b.coordinate, value, a == b);
      }
    }
  }
}
}  // namespace detail

/// dM/dx_j, j = 0..d-1, into dM (d^3 values: matrix j row-major at j d^2)
/// from the kinematics and composite inertias in ws (crba first); see the
/// header comment.
template <typename Scalar>
void massMatrixDerivativesFromCrba(const BodyModel& model, BodyWorkspace<Scalar>& ws, Scalar* dM)
{
  const std::size_t d = model.coordinates;
  std::fill(dM, dM + d * d * d, Scalar(0));
  detail::addCarriedMomentumTerms(model, ws, dM);
  detail::addCarriedInertiaTerms(model, ws, dM);
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
/// massMatrixDerivatives.
void massMatrixDerivativesRowMajor(const BodyModel& model, BodyWorkspace<double>& ws, const double* x, double* dM);

extern template void massMatrixDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*, double*);

}  // namespace diff_rigid_body
