// Backprop over a body's vertices stored coordinate by coordinate.
//
// The backprop of vertex_jacobian.h needs two sums per body,
//   W = sum_i g_i p0_i^T (3x3)   and   force = sum_i g_i,
// then dL/dq = backpropFromSums(pose, W, force). The gradients g_i come from
// the client as (x, y, z) per vertex; the vertices p0_i are ours, so they can
// be stored in the layout the sum wants: a structure of arrays
// (VertexColumns, types.h), made once per body. One vector load then holds
// the x (y, z) of 8 vertices (AVX-512) or 4 (AVX2) with no transposition;
// only the gradients are transposed into lanes (detail/backprop_sums.h).
//
// Large meshes can be split over threads: the vertices are cut into
// contiguous chunks whose sums are added in chunk order, so for a given
// vertex count, thread count and CPU path the result is always the same.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "diff_rigid_body/algorithm/detail/backprop_sums.h"
#include "diff_rigid_body/types.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"

namespace diff_rigid_body
{
/// Below this many vertices per thread a thread costs more than it saves
/// (starting one is ~10-50 us; 2^16 vertices take ~100 us on one core).
constexpr std::size_t kMinVerticesPerBackpropThread = std::size_t(1) << 16;

namespace detail
{
/// Threads worth using for `count` vertices: at most `threads`, at least 1.
inline std::size_t backpropChunks(std::size_t count, unsigned threads)
{
  return std::max<std::size_t>(1, std::min<std::size_t>(threads, count / kMinVerticesPerBackpropThread));
}

inline ByCoordinate byCoordinate(const VertexColumns<double>& columns)
{
  return { columns.col(0).data(), columns.col(1).data(), columns.col(2).data() };
}
}  // namespace detail

/// W = sum_i g_i p0_i^T and force = sum_i g_i over all vertices, on up to
/// `threads` threads (the calling one included); fewer when the mesh has
/// under kMinVerticesPerBackpropThread vertices per thread.
///
/// \param gradients dL/dp, 3 per vertex in vertex order [any unit / m]
inline VertexGradientSums sumVertexGradients(const VertexColumns<double>& columns, const double* gradients,
                                             unsigned threads = 1)
{
  const std::size_t count = static_cast<std::size_t>(columns.rows());
  return VertexGradientSums(detail::gradientSumsInChunks(detail::byCoordinate(columns), gradients, count,
                                                         detail::backpropChunks(count, threads)));
}

/// dL/dq = sum_i J_i^T g_i over all vertices of a body stored by coordinate
/// (same result as backpropagateVertexGradients of vertex_jacobian.h up to
/// the order of the additions).
inline Vector6<double> backpropagateVertexGradients(const BodyPose<double>& pose, const VertexColumns<double>& columns,
                                                    const double* gradients, unsigned threads = 1)
{
  const VertexGradientSums sums = sumVertexGradients(columns, gradients, threads);
  return backpropFromSums(pose, sums.W, sums.force);
}

/// The same over the selected vertices `indices` of `columns` (empty means
/// all, in order; indices must already be validated), with `gradients` in
/// the order of `indices`: one call for a whole request, whichever vertices
/// it selects. A selection is gathered vertex by vertex, on one thread.
inline Vector6<double> backpropagateVertexGradients(const BodyPose<double>& pose, const VertexColumns<double>& columns,
                                                    const std::vector<std::uint32_t>& indices,
                                                    const double* gradients, unsigned threads = 1)
{
  if (indices.empty())
    return backpropagateVertexGradients(pose, columns, gradients, threads);
  const detail::Gathered<detail::ByCoordinate> selected{ detail::byCoordinate(columns), indices.data() };
  return backpropFromSums(pose, detail::gradientSumsInChunks(selected, gradients, indices.size(), 1));
}

/// A Matrix3X (3 x N, one vertex per column) would convert silently to a
/// VertexColumns (N x 3) here and be read as the wrong coordinates: refused
/// at compile time. Use backpropagateVertexGradients(pose, vertices, indices,
/// gradients) of vertex_jacobian.h, or transpose the vertices once.
Vector6<double> backpropagateVertexGradients(const BodyPose<double>& pose, const Matrix3X<double>& vertices,
                                             const double* gradients, unsigned threads = 1) = delete;

}  // namespace diff_rigid_body
