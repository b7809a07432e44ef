#include "diff_rigid_body/articulated_queries.h"

#include <algorithm>

#include <unsupported/Eigen/AutoDiff>

#include "diff_rigid_body/detail/backprop_sums.h"

namespace diff_rigid_body
{
std::size_t ArticulatedBody::segmentOfVertex(std::uint32_t v) const
{
  // Segments' vertex ranges are contiguous and in segment order.
  const auto after = std::upper_bound(segments.begin(), segments.end(), v,
                                      [](std::uint32_t vertex, const Segment& s) { return vertex < s.vertex_begin; });
  return static_cast<std::size_t>(after - segments.begin()) - 1;
}

std::vector<Eigen::MatrixXd> articulatedMassMatrixDerivatives(const ArticulatedBody& body, const double* x)
{
  // One forward-mode direction per coordinate: value and d/dx_j together.
  using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;
  const std::size_t dofs = body.dofs();
  std::vector<Dual> seeded(dofs);
  for (std::size_t i = 0; i < dofs; ++i)
    seeded[i] = Dual(x[i], Eigen::Matrix<double, 1, 1>::Zero());
  std::vector<Eigen::MatrixXd> derivatives(dofs, Eigen::MatrixXd(dofs, dofs));
  for (std::size_t j = 0; j < dofs; ++j)
  {
    seeded[j].derivatives()[0] = 1.0;
    const Eigen::Matrix<Dual, Eigen::Dynamic, Eigen::Dynamic> M = articulatedMassMatrix(body, seeded.data());
    for (Eigen::Index r = 0; r < M.rows(); ++r)
      for (Eigen::Index c = 0; c < M.cols(); ++c)
        derivatives[j](r, c) = M(r, c).derivatives().size() ? M(r, c).derivatives()[0] : 0.0;
    seeded[j].derivatives()[0] = 0.0;
  }
  return derivatives;
}

namespace
{
/// Every coordinate's motion of one segment: dp/dx = V + W x (p - r)
/// column by column (V, W: 3 x dof; the twists of the joints on its path,
/// times their mimic multipliers, summed per coordinate).
struct SegmentMotion
{
  Eigen::Matrix<double, 3, Eigen::Dynamic> V;
  Eigen::Matrix<double, 3, Eigen::Dynamic> W;
};

/// V and W restricted to the written columns, rows contiguous, so that a
/// vertex's J = V + W x d is written row by row with vector operations.
struct WrittenMotion
{
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> V;
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> W;
};

std::vector<SegmentMotion> segmentMotions(const ArticulatedBody& body, const ArticulatedPose<double>& pose)
{
  const Eigen::Index dofs = static_cast<Eigen::Index>(body.dofs());
  std::vector<SegmentMotion> motions(body.segments.size());
  for (std::size_t s = 0; s < body.segments.size(); ++s)
  {
    const Segment& segment = body.segments[s];
    SegmentMotion& motion = motions[s];
    if (segment.parent >= 0)
      motion = motions[static_cast<std::size_t>(segment.parent)];
    else
    {
      motion.V = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, dofs);
      motion.W = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, dofs);
      if (body.floating_root)
      {
        motion.W.leftCols<3>() = pose.root_T;
        motion.V.middleCols<3>(3).setIdentity();
      }
    }
    if (segment.coordinate >= 0)
    {
      motion.V.col(segment.coordinate) += segment.multiplier * pose.joint_twists[s].v;
      motion.W.col(segment.coordinate) += segment.multiplier * pose.joint_twists[s].w;
    }
  }
  return motions;
}

/// Calls visit(vertex slot k, vertex index v, segment s) for the selected vertices.
template <typename Visit>
void forEachVertex(const ArticulatedBody& body, const std::vector<std::uint32_t>& vertices, Visit visit)
{
  if (!vertices.empty())
  {
    for (std::size_t k = 0; k < vertices.size(); ++k)
      visit(k, vertices[k], body.segmentOfVertex(vertices[k]));
    return;
  }
  for (std::size_t s = 0; s < body.segments.size(); ++s)
  {
    const std::uint32_t end = body.segments[s].vertex_begin + body.segments[s].vertex_count;
    for (std::uint32_t v = body.segments[s].vertex_begin; v < end; ++v)
      visit(v, v, s);
  }
}
}  // namespace

void articulatedVertexJacobians(const ArticulatedBody& body, const ArticulatedPose<double>& pose,
                                const std::vector<std::uint32_t>& vertices, const std::vector<int>& columns,
                                double* positions, double* jacobians)
{
  const std::vector<SegmentMotion> motions = segmentMotions(body, pose);
  std::vector<int> all_columns;
  if (columns.empty())
    for (std::size_t c = 0; c < body.dofs(); ++c)
      all_columns.push_back(static_cast<int>(c));
  const std::vector<int>& written = columns.empty() ? all_columns : columns;
  const Eigen::Index width = static_cast<Eigen::Index>(written.size());
  std::vector<WrittenMotion> selected(motions.size());
  for (std::size_t s = 0; s < motions.size(); ++s)
  {
    selected[s].V.resize(3, width);
    selected[s].W.resize(3, width);
    for (Eigen::Index c = 0; c < width; ++c)
    {
      selected[s].V.col(c) = motions[s].V.col(written[static_cast<std::size_t>(c)]);
      selected[s].W.col(c) = motions[s].W.col(written[static_cast<std::size_t>(c)]);
    }
  }
  forEachVertex(body, vertices, [&](std::size_t k, std::uint32_t v, std::size_t s) {
    const SegmentFrame<double>& frame = pose.frames[s];
    const Eigen::Vector3d p = frame.R * body.vertices.col(v) + frame.p;
    Eigen::Map<Eigen::Vector3d>(positions + 3 * k) = p;
    if (!jacobians)
      return;
    // Row i of V + W x d: (w x d)_x = w_y d_z - w_z d_y, and cyclically.
    const Eigen::Vector3d d = p - pose.reference;
    const double *V = selected[s].V.data(), *W = selected[s].W.data();
    double* J = jacobians + 3 * width * k;
    for (Eigen::Index c = 0; c < width; ++c)
    {
      J[c] = V[c] + (d[2] * W[width + c] - d[1] * W[2 * width + c]);
      J[width + c] = V[width + c] + (d[0] * W[2 * width + c] - d[2] * W[c]);
      J[2 * width + c] = V[2 * width + c] + (d[1] * W[c] - d[0] * W[width + c]);
    }
  });
}

void articulatedBackprop(const ArticulatedBody& body, const ArticulatedPose<double>& pose,
                         const std::vector<std::uint32_t>& vertices, const double* gradients, double* gradient)
{
  // Per segment: G = sum g and H = sum (p - r) x g (see articulated_queries.h).
  // With p - r = R p0 + (p_s - r) and W = sum g p0^T (for a whole segment one
  // pass over its vertices), A = sum g (R p0)^T = W R^T gives
  // sum (R p0) x g = (A_zy - A_yz, A_xz - A_zx, A_yx - A_xy).
  const std::size_t n = body.segments.size();
  std::vector<Eigen::Vector3d> G(n, Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> outer(n, Eigen::Matrix3d::Zero());
  if (vertices.empty())
    for (std::size_t s = 0; s < n; ++s)
    {
      // The free body's summation engine (detail/backprop_sums.h): W[3a + b] = sum g_a p0_b, then G.
      const Segment& segment = body.segments[s];
      const detail::GradientSums12 sums =
          detail::gradientSums(detail::ByVertex{ body.vertices.data() + 3 * std::size_t(segment.vertex_begin) },
                               detail::ByVertex{ gradients + 3 * std::size_t(segment.vertex_begin) },
                               segment.vertex_count);
      outer[s] = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(sums.data());
      G[s] << sums[9], sums[10], sums[11];
    }
  else
    for (std::size_t k = 0; k < vertices.size(); ++k)
    {
      const std::size_t s = body.segmentOfVertex(vertices[k]);
      const Eigen::Vector3d g = Eigen::Map<const Eigen::Vector3d>(gradients + 3 * k);
      G[s] += g;
      outer[s].noalias() += g * body.vertices.col(vertices[k]).transpose();
    }
  std::vector<Eigen::Vector3d> H(n);
  for (std::size_t s = 0; s < n; ++s)
  {
    const Eigen::Matrix3d A = outer[s] * pose.frames[s].R.transpose();
    H[s] = Eigen::Vector3d(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1)) +
           (pose.frames[s].p - pose.reference).cross(G[s]);
  }
  // Subtree sums (children come after their parents), then each joint's
  // coordinate gets m_j (v_j . G + w_j . H) of the subtree it moves.
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
    const Segment& segment = body.segments[s];
    if (segment.coordinate >= 0)
      gradient[segment.coordinate] +=
          segment.multiplier * (pose.joint_twists[s].v.dot(G[s]) + pose.joint_twists[s].w.dot(H[s]));
  }
}

}  // namespace diff_rigid_body
