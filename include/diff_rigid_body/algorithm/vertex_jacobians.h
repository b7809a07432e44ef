// Vertex positions and Jacobians J = dp/dx of a body (body_model.h), in
// double, stored as double or float.
//
// A vertex p0 of segment s (in its frame) is at p = R_s p0 + p_s, and
//   dp/dx_c = V_c + W_c x (p - r),   (W_c; V_c) = sum m_k S_k
// over the dofs k on s's path to the root that x_c drives (kinematics.h),
// so the work per vertex is the answer's: 3 values per written column. The
// columns (V_c, W_c) of a segment come from one walk up the parent array
// and are shared by all of its vertices; a list of vertices in any order
// redoes that walk only where the segment changes. Nothing is allocated
// per call.
//
// Overflow is ruled out in advance: vertexOutputBound bounds every output
// of a configuration (positions by |p_s|_inf + r_s, J columns by
// |V_c| + |W_c| (|p_s - r| + r_s), r_s the segment's vertex radius), so
// the node refuses a configuration before anything is written.
//
// A free object takes the closed forms of free_body/vertex_jacobian.h
// (J = [ -[R p0]_x T | I3 ], SIMD), whose bound is |t|_inf + r.
#pragma once

#include <cstdint>
#include <vector>

#include "diff_rigid_body/multibody/body_workspace.h"

namespace diff_rigid_body
{
/// Which columns of J a query writes: all of x, or the compact transport's
/// (a free root's translation columns x[3..5], always I3, left out).
struct JacobianColumns
{
  std::vector<int> of_coordinate;  ///< column of x_c in the answer, -1 if not written
  std::size_t width = 0;           ///< written columns per row

  /// Every column, in x order.
  static JacobianColumns all(const BodyModel& model);
  /// The compact transport's: every column but a free root's x[3..5].
  static JacobianColumns compact(const BodyModel& model);
};

/// Largest |value| that a position or written J entry of `vertices` (empty
/// = all) can take at x, rounding included; +inf if the kinematics at x is
/// not finite. Leaves the kinematics at x in ws (except for a free object).
double vertexOutputBound(const BodyModel& model, BodyWorkspace<double>& ws, const JacobianColumns& columns,
                         const std::vector<std::uint32_t>& vertices, const double* x);

/// Positions (3 per vertex, fixed frame) and, unless `jacobians` is null,
/// the written columns of J (3 x width per vertex, row-major) of `vertices`
/// (empty = all, in order; indices already checked) at x, stored as Out
/// (double or float). Check vertexOutputBound first.
template <typename Out>
void vertexJacobians(const BodyModel& model, BodyWorkspace<double>& ws, const JacobianColumns& columns,
                     const std::vector<std::uint32_t>& vertices, const double* x, Out* positions, Out* jacobians);

extern template void vertexJacobians<double>(const BodyModel&, BodyWorkspace<double>&, const JacobianColumns&,
                                             const std::vector<std::uint32_t>&, const double*, double*, double*);
extern template void vertexJacobians<float>(const BodyModel&, BodyWorkspace<double>&, const JacobianColumns&,
                                            const std::vector<std::uint32_t>&, const double*, float*, float*);

}  // namespace diff_rigid_body
