// A reference for bench_articulated.cpp, not on the node's path: the
// articulated backprop through the free body's engine (detail/backprop_sums.h),
// to show what the per-vertex pass costs when it is the 12 sums.
//
// Per segment s, over its vertex range (p0 in the segment frame, by coordinate):
//   W_s = sum g p0^T,  G_s = sum g                       (the 12 sums)
//   H_s = sum (p - r) x g = sum (R p0) x g + (p_s - r) x G_s,
//   sum (R p0) x g = vee(A - A^T) with A = R W_s^T, i.e.
//   (A_12 - A_21, A_20 - A_02, A_01 - A_10)
// then, as articulated_queries.h: subtree sums of G and H, and
//   dL/dx_c = sum m_j (v_j . G + w_j . H) over the joints j that x_c drives.
#pragma once

#include <algorithm>
#include <vector>

#include "diff_rigid_body/articulated_kinematics.h"
#include "diff_rigid_body/vertex_columns.h"

namespace drb_bench
{
/// dL/dx (body.dofs() values into `gradient`) for gradients of every vertex
/// (3 per vertex, body order); `columns` = body.vertices by coordinate.
inline void backpropBySums(const drb::ArticulatedBody& body, const drb::ArticulatedPose<double>& pose,
                           const drb::VertexColumns<double>& columns, const double* gradients, double* gradient)
{
  const std::size_t n = body.segments.size();
  std::vector<Eigen::Vector3d> G(n), H(n);
  const drb::detail::ByCoordinate all = drb::detail::byCoordinate(columns);
  for (std::size_t s = 0; s < n; ++s)
  {
    const drb::Segment& segment = body.segments[s];
    const drb::detail::GradientSums12 sums = drb::detail::gradientSums(
        all.from(segment.vertex_begin), drb::detail::ByVertex{ gradients + 3 * segment.vertex_begin },
        segment.vertex_count);
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> W(sums.data());
    const Eigen::Matrix3d A = pose.frames[s].R * W.transpose();
    G[s] << sums[9], sums[10], sums[11];
    H[s] = Eigen::Vector3d(A(1, 2) - A(2, 1), A(2, 0) - A(0, 2), A(0, 1) - A(1, 0)) +
           (pose.frames[s].p - pose.reference).cross(G[s]);
  }
  for (std::size_t s = n; s-- > 1;)
  {
    const std::size_t parent = static_cast<std::size_t>(body.segments[s].parent);
    G[parent] += G[s];
    H[parent] += H[s];
  }
  std::fill(gradient, gradient + body.dofs(), 0.0);
  if (body.floating_root)
    for (int k = 0; k < 3; ++k)
    {
      gradient[k] = pose.root_T.col(k).dot(H[0]);
      gradient[k + 3] = G[0][k];
    }
  for (std::size_t s = 0; s < n; ++s)
  {
    const drb::Segment& segment = body.segments[s];
    if (segment.coordinate >= 0)
      gradient[segment.coordinate] +=
          segment.multiplier * (pose.joint_twists[s].v.dot(G[s]) + pose.joint_twists[s].w.dot(H[s]));
  }
}

}  // namespace drb_bench
