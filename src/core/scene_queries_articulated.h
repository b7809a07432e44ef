// Helpers of scene_queries.cpp for articulated bodies (articulated_*.h):
// answer layouts and the finiteness checks. Internal to the core.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "diff_rigid_body/articulated_kinematics.h"
#include "diff_rigid_body/articulated_queries.h"

namespace diff_rigid_body
{
namespace detail
{
/// Copies a d x d matrix row-major into `out` (d^2 values).
inline void writeRowMajor(const Eigen::MatrixXd& M, double* out)
{
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(out, M.rows(), M.cols()) = M;
}

/// M(x_k) and cos_theta of an articulated body for x_k = x + k stride,
/// k < count: matrix k (d^2 values, row-major) at mass_matrices + k m_stride,
/// cos_theta[k cos_stride] = cos(x_k[1]) with a floating root, else 1.
inline void articulatedMassMatrices(const ArticulatedBody& body, const double* x, std::size_t count,
                                    std::size_t stride, std::size_t m_stride, std::size_t cos_stride,
                                    double* mass_matrices, double* cos_theta)
{
  for (std::size_t k = 0; k < count; ++k)
  {
    const double* xk = x + k * stride;
    writeRowMajor(articulatedMassMatrix(body, xk), mass_matrices + k * m_stride);
    cos_theta[k * cos_stride] = body.floating_root ? std::cos(xk[THETA]) : 1.0;
  }
}

/// dM/dx_j, j = 0..d-1, at x: d^3 values, each d x d row-major.
inline void articulatedMassMatrixDerivativesRowMajor(const ArticulatedBody& body, const double* x, double* out)
{
  const std::size_t d = body.dofs();
  const std::vector<Eigen::MatrixXd> dM = articulatedMassMatrixDerivatives(body, x);
  for (std::size_t j = 0; j < d; ++j)
    writeRowMajor(dM[j], out + j * d * d);
}

/// The Jacobian columns of the compact transport: all but a floating root's
/// translation (x[3..5]); empty (= all) for a fixed-base body.
inline std::vector<int> compactColumnList(const ArticulatedBody& body)
{
  std::vector<int> columns;
  if (!body.floating_root)
    return columns;
  for (int c = 0; c < static_cast<int>(body.dofs()); ++c)
    if (c < TX || c > TZ)
      columns.push_back(c);
  return columns;
}

/// Whether every segment frame, joint twist, the reference point and a floating root's T are finite.
inline bool poseIsFinite(const ArticulatedBody& body, const ArticulatedPose<double>& pose)
{
  for (const SegmentFrame<double>& frame : pose.frames)
    if (!frame.R.allFinite() || !frame.p.allFinite())
      return false;
  for (std::size_t s = 0; s < pose.joint_twists.size(); ++s)
    if (body.segments[s].coordinate >= 0 && !(pose.joint_twists[s].w.allFinite() && pose.joint_twists[s].v.allFinite()))
      return false;
  return pose.reference.allFinite() && (!body.floating_root || pose.root_T.allFinite());
}

/// Index of the first value with |value| > max(Out) or not finite; values.size() if none.
template <typename Out>
std::size_t firstValueBeyond(const std::vector<double>& values)
{
  constexpr double kLimit = std::numeric_limits<Out>::max();
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!(std::abs(values[i]) <= kLimit))
      return i;
  return values.size();
}

}  // namespace detail
}  // namespace diff_rigid_body
