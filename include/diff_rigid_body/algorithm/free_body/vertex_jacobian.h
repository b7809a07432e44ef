// Vertex positions, vertex Jacobians and their vector-Jacobian product for
// many vertices at once, templated on the scalar (pose and J: body_pose.h;
// one vertex at a time, for tests: test/reference/vertex_kernels.h).
//
//   p = R(r) p0 + t,   J = dp/dq = [ -[R p0]_x T | I3 ]
//
// Backprop (vector-Jacobian product), given g_i = dL/dp_i:
//   dL/dr = T^T sum_i (R p0_i) x g_i,   dL/dt = sum_i g_i.
// With W = sum_i g_i p0_i^T (3x3) and X = R W^T = sum_i (R p0_i) g_i^T,
//   sum_i (R p0_i) x g_i = (X12 - X21, X20 - X02, X01 - X10),
// so the per-vertex work is one 3x3 rank-1 update; J is never formed.
//
// In double the loops below hand over to the SIMD kernels of detail/
// (vertex_kernels_sse2.h for positions and J, backprop_sums.h for W and
// force); every other scalar runs the portable loops.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "diff_rigid_body/algorithm/free_body/pose.h"
#include "diff_rigid_body/algorithm/detail/backprop_sums.h"
#include "diff_rigid_body/algorithm/detail/vertex_kernels_sse2.h"
#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
namespace detail
{
/// Number of selected vertices: indices.size(), or every vertex when empty.
template <typename Scalar>
std::size_t selectedCount(const Matrix3X<Scalar>& vertices, const std::vector<std::uint32_t>& indices)
{
  return indices.empty() ? static_cast<std::size_t>(vertices.cols()) : indices.size();
}

/// Writes the outputs of every selected vertex n (Cols: see writeVertexOutputs).
template <int Cols, typename Scalar, typename Out>
void writeSelectedVertices(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                           const std::vector<std::uint32_t>& indices, Out* positions, Out* jacobians)
{
  const std::size_t count = selectedCount(vertices, indices);
  for (std::size_t n = 0; n < count; ++n)
  {
    const Eigen::Index v = indices.empty() ? static_cast<Eigen::Index>(n) : static_cast<Eigen::Index>(indices[n]);
    writeVertexOutputs<Cols>(pose, rotate(pose.R, vertices.col(v)), positions ? positions + 3 * n : nullptr,
                             jacobians ? jacobians + 3 * Cols * n : nullptr);
  }
}
}  // namespace detail

/// Positions (3 per vertex) and Jacobians (18 per vertex, 3x6 row-major) for
/// the selected vertices, written to caller-owned buffers.
///
/// \param vertices  body-frame vertices, one per column [m]
/// \param indices   vertices to evaluate; empty means all, in order. Indices
///                  must already be validated (< vertices.cols()).
/// \param positions out, 3 * count values, or nullptr to skip
/// \param jacobians out, 18 * count values, or nullptr to skip
///
/// In double, outputs of kStreamingStoreBytes or more are written with
/// streaming stores (detail/vertex_kernels_sse2.h).
template <typename Scalar>
void vertexPositionsAndJacobians(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                 const std::vector<std::uint32_t>& indices, Scalar* positions, Scalar* jacobians)
{
  if constexpr (std::is_same<Scalar, double>::value)
  {
    if (detail::positionsAndJacobiansSimd(pose, vertices, indices, positions, jacobians))
      return;
  }
  detail::writeSelectedVertices<6>(pose, vertices, indices, positions, jacobians);
}

/// Reduced transport of vertexPositionsAndJacobians: J = [ Jr | I3 ] always
/// has the identity as its translation block, so only the rotation block
/// Jr = dp/d(phi, theta, psi) is written, 9 values per vertex (3x3
/// row-major: row i = dp_i/d(phi, theta, psi)). Computed in Scalar and
/// stored as Out (e.g. float for a float32 transport); the values equal
/// those of vertexPositionsAndJacobians before the conversion.
///
/// \param positions          out, 3 * count values, or nullptr to skip
/// \param rotation_jacobians out, 9 * count values, or nullptr to skip
template <typename Scalar, typename Out>
void vertexPositionsAndRotationJacobians(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                         const std::vector<std::uint32_t>& indices, Out* positions,
                                         Out* rotation_jacobians)
{
  detail::writeSelectedVertices<3>(pose, vertices, indices, positions, rotation_jacobians);
}

/// dL/dq from the two per-body sums of the backprop (see the top of this
/// file): W = sum_i g_i p0_i^T and force = sum_i g_i.
///   dL/dr = T^T (X12 - X21, X20 - X02, X01 - X10) with X = R W^T,
///   dL/dt = force.
template <typename Scalar>
Vector6<Scalar> backpropFromSums(const BodyPose<Scalar>& pose, const Matrix3<Scalar>& W, const Vector3<Scalar>& force)
{
  const Matrix3<Scalar> X = pose.R * W.transpose();  // sum_i (R p0_i) g_i^T
  const Vector3<Scalar> torque(X(1, 2) - X(2, 1), X(2, 0) - X(0, 2), X(0, 1) - X(1, 0));
  Vector6<Scalar> dL_dq;
  dL_dq.template head<3>() = pose.T.transpose() * torque;
  dL_dq.template tail<3>() = force;
  return dL_dq;
}

/// The 12 sums of the double engine (detail/backprop_sums.h) over some vertices:
/// W = sum_i g_i p0_i^T (the first nine, row-major) and force = sum_i g_i.
struct VertexGradientSums
{
  explicit VertexGradientSums(const detail::GradientSums12& sums)
    : W(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(sums.data()))
    , force(sums[9], sums[10], sums[11])
  {
  }
  Matrix3<double> W;
  Vector3<double> force;
};

/// dL/dq from the 12 sums of the double engine.
inline Vector6<double> backpropFromSums(const BodyPose<double>& pose, const detail::GradientSums12& sums)
{
  const VertexGradientSums split(sums);
  return backpropFromSums(pose, split.W, split.force);
}

/// dL/dq = sum_i J_i^T g_i without forming J.
///
/// \param gradients dL/dp for each selected vertex, 3 per vertex, in the
///                  order of `indices` (or of all vertices when empty).
template <typename Scalar>
Vector6<Scalar> backpropagateVertexGradients(const BodyPose<Scalar>& pose, const Matrix3X<Scalar>& vertices,
                                             const std::vector<std::uint32_t>& indices, const Scalar* gradients)
{
  const std::size_t count = detail::selectedCount(vertices, indices);
  if constexpr (std::is_same<Scalar, double>::value)
  {
    const detail::ByVertex by_vertex{ vertices.data() };
    return backpropFromSums(pose, indices.empty() ?
                                      detail::gradientSumsInChunks(by_vertex, gradients, count, 1) :
                                      detail::gradientSumsInChunks(detail::Gathered<detail::ByVertex>{ by_vertex,
                                                                                                      indices.data() },
                                                                   gradients, count, 1));
  }
  else
  {
    Matrix3<Scalar> W = Matrix3<Scalar>::Zero();      // sum_i g_i p0_i^T
    Vector3<Scalar> force = Vector3<Scalar>::Zero();  // sum_i g_i
    for (std::size_t n = 0; n < count; ++n)
    {
      const Eigen::Index v = indices.empty() ? static_cast<Eigen::Index>(n) : static_cast<Eigen::Index>(indices[n]);
      const Eigen::Map<const Vector3<Scalar>> g(gradients + 3 * n);
      W.noalias() += g * vertices.col(v).transpose();
      force += g;
    }
    return backpropFromSums(pose, W, force);
  }
}

}  // namespace diff_rigid_body
