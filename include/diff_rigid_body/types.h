// Types shared by the whole core: fixed-size Eigen vectors and matrices
// templated on the scalar, vertex sets, and the order of the state q.
// Plain Eigen only (no SIMD intrinsics), so that any header may include it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products, Isometry3d

namespace diff_rigid_body
{
template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Vector6 = Eigen::Matrix<Scalar, 6, 1>;
template <typename Scalar>
using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
template <typename Scalar>
using Matrix6 = Eigen::Matrix<Scalar, 6, 6>;
template <typename Scalar>
using Matrix36 = Eigen::Matrix<Scalar, 3, 6>;

/// Points, one per column (e.g. body-frame vertices [m]).
template <typename Scalar>
using Matrix3X = Eigen::Matrix<Scalar, 3, Eigen::Dynamic>;

/// Body-frame vertices, column 0 every x, column 1 every y, column 2 every
/// z [m] (Eigen's column-major N x 3). Make it once per body:
/// `VertexColumns<double> columns = vertices.transpose();` (24 B per vertex).
template <typename Scalar>
using VertexColumns = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;

/// Indices into q = (phi, theta, psi, tx, ty, tz).
enum StateIndex : int
{
  PHI = 0,
  THETA = 1,
  PSI = 2,
  TX = 3,
  TY = 4,
  TZ = 5
};

}  // namespace diff_rigid_body
