// The joint-space mass matrix M(x) of a body by the composite-rigid-body
// algorithm (Featherstone, "Rigid Body Dynamics Algorithms", 2008, ch. 6),
// in the fixed frame about the reference point r (spatial.h, kinematics.h).
//
// Kinetic energy T = 1/2 x'^T M x' = sum over segments of 1/2 (m |v_COM|^2 + w^T I w).
// With Ic_s the inertia of segment s's subtree about r and S_k the unit
// motion of dof k, the dofs a and b with a an ancestor of b (or b itself)
// both move b's subtree, so
//   M(c_a, c_b) += m_a m_b S_a . (Ic_seg(b) S_b)     (and M(c_b, c_a) for a != b),
// c the coordinate and m the multiplier of a dof. Each dof's momentum
// F_b = Ic_seg(b) S_b is formed once and paired with the motions up its
// path, following the parent array: O(dofs x depth).
//
// The recursion runs in motion coordinates (body_model.h) and gives H, the
// mass matrix in nu; M(x) = A^T H A (motion_coordinates.h). For a free root
// (x = q of version 1) the 6 x 6 block of M is blockdiag(T^T I' T, m I3)
// when the body is one segment (docs/derivation.md); a free object takes
// that closed form (free_body/mass_matrix.h) in massMatrices.
#pragma once

#include "diff_rigid_body/algorithm/kinematics.h"
#include "diff_rigid_body/multibody/motion_coordinates.h"

namespace diff_rigid_body
{
namespace detail
{
/// ws.body_inertia: each segment's own inertia about ws.r; ws.composite:
/// its subtree's, children first.
template <typename Scalar>
void compositeInertias(const BodyModel& model, BodyWorkspace<Scalar>& ws)
{
  for (std::size_t s = model.segments.size(); s-- > 0;)
  {
    const Segment& segment = model.segments[s];
    Inertia<Scalar>& own = ws.body_inertia[s];
    if (segment.inertia.mass > 0.0)
      own = spatial::inertiaAbout(ws.r, ws.R[s], ws.p[s], segment.inertia.mass, segment.inertia.com,
                                  segment.inertia.inertia);
    else
      own = Inertia<Scalar>();
    ws.composite[s] = own;
  }
  for (std::size_t s = model.segments.size(); s-- > 1;)
    spatial::add(ws.composite[static_cast<std::size_t>(model.segments[s].parent)], ws.composite[s]);
}
}  // namespace detail

/// H, the mass matrix in motion coordinates, into ws.H (d x d, symmetric)
/// from the kinematics already in ws (forwardKinematics); also leaves
/// ws.body_inertia, ws.composite and ws.momentum.
template <typename Scalar>
void crbaFromKinematics(const BodyModel& model, BodyWorkspace<Scalar>& ws)
{
  detail::compositeInertias(model, ws);
  ws.H.setZero();
  for (std::size_t b = 0; b < model.dofs.size(); ++b)
  {
    const Dof& deeper = model.dofs[b];
    const Force<Scalar>& F = ws.momentum[b] =
        spatial::momentum(ws.composite[static_cast<std::size_t>(deeper.segment)], ws.S[b]);
    const Eigen::Index cb = deeper.coordinate;
    for (int a = static_cast<int>(b); a >= 0; a = model.dofs[static_cast<std::size_t>(a)].parent)
    {
      const Dof& upper = model.dofs[static_cast<std::size_t>(a)];
      const Scalar value = Scalar(upper.multiplier * deeper.multiplier) * spatial::power(ws.S[static_cast<std::size_t>(a)], F);
      const Eigen::Index ca = upper.coordinate;
      ws.H(ca, cb) += value;
      if (a != static_cast<int>(b))
        ws.H(cb, ca) += value;
    }
  }
}

/// M(x) into ws.M (and H into ws.H): forward kinematics, crbaFromKinematics,
/// then M = A^T H A.
template <typename Scalar>
void crba(const BodyModel& model, BodyWorkspace<Scalar>& ws, const Scalar* x)
{
  forwardKinematics(model, ws, x);
  crbaFromKinematics(model, ws);
  massMatrixToCoordinates(model, ws);
}

/// The node's M for K configurations x_k = x + k stride, k < count: matrix k
/// (d^2 values, row-major) at mass_matrices + k m_stride, and
/// cos_theta[k cos_stride] = cos(theta_k) for a free root, 1 for a fixed
/// base. A free object takes the closed form of free_body/mass_matrix.h
/// (batched, vectorised sines and cosines); any other body crba.
void massMatrices(const BodyModel& model, BodyWorkspace<double>& ws, const double* x, std::size_t count,
                  std::size_t stride, std::size_t m_stride, std::size_t cos_stride, double* mass_matrices,
                  double* cos_theta);

extern template void crba<double>(const BodyModel&, BodyWorkspace<double>&, const double*);
extern template void crbaFromKinematics<double>(const BodyModel&, BodyWorkspace<double>&);

}  // namespace diff_rigid_body
