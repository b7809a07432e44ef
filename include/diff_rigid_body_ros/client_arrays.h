// How diff_rigid_body_ros::RigidBodyClient (rigid_body_client.h) lays out
// request arrays and sizes response arrays: one configuration x of a body
// (d values), K configurations concatenated, vertex counts. Eigen only.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body_ros/client_types.h"

namespace diff_rigid_body_ros
{
namespace detail
{
/// The values of one configuration x.
template <typename Derived>
std::vector<double> values(const Eigen::MatrixBase<Derived>& x)
{
  const Eigen::VectorXd evaluated = x;
  return std::vector<double>(evaluated.data(), evaluated.data() + evaluated.size());
}

/// A single request's q: empty (the current state) or the 6 values of *q.
inline std::vector<double> optionalQ(const Vector6d* q)
{
  return q ? values(*q) : std::vector<double>();
}

/// The values of K configurations, concatenated (K >= 1: an empty q would mean the current state).
template <typename Vector>
std::vector<double> flatten(const std::vector<Vector>& qs)
{
  if (qs.empty())
    throw std::invalid_argument("qs: at least one configuration");
  std::vector<double> q;
  for (const Vector& one : qs)
    q.insert(q.end(), one.data(), one.data() + one.size());
  return q;
}

/// flatten, or empty (zeros, or the current state) for no configuration.
template <typename Vector>
std::vector<double> flattenOptional(const std::vector<Vector>& qs)
{
  return qs.empty() ? std::vector<double>() : flatten(qs);
}

/// Enables an overload for Eigen vectors (Vector6d, Eigen::VectorXd, ...), as template parameter
/// `detail::IfEigenVector<Vector> = 0`: a flat std::vector<double> or a braced list keeps the
/// overload that takes std::vector<double>.
template <typename Vector>
using IfEigenVector = std::enable_if_t<std::is_base_of<Eigen::MatrixBase<Vector>, Vector>::value, int>;

/// dL/dp blocks (3 x N each, one per configuration) as a backprop request's gradients field
/// (K x N x 3, configuration-major).
inline std::vector<double> flattenGradients(const std::vector<const Eigen::Matrix3Xd*>& dL_dp)
{
  std::vector<double> gradients;
  for (const Eigen::Matrix3Xd* block : dL_dp)
    gradients.insert(gradients.end(), block->data(), block->data() + block->size());
  return gradients;
}
inline std::vector<double> flattenGradients(const std::vector<Eigen::Matrix3Xd>& dL_dp)
{
  std::vector<const Eigen::Matrix3Xd*> blocks;
  for (const Eigen::Matrix3Xd& block : dL_dp)
    blocks.push_back(&block);
  return flattenGradients(blocks);
}

/// N from the size of a K x N x 3 positions field.
inline Eigen::Index vertexCount(std::size_t position_values, std::size_t configurations)
{
  return configurations ? static_cast<Eigen::Index>(position_values / (3 * configurations)) : 0;
}

/// The float64 or the float32 field of a compact response.
template <typename Scalar>
const std::vector<Scalar>& compactField(const std::vector<double>& f64, const std::vector<float>& f32)
{
  if constexpr (std::is_same<Scalar, float>::value)
    return f32;
  else
    return f64;
}

}  // namespace detail
}  // namespace diff_rigid_body_ros
