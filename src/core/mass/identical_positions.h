// Joining points at identical positions: the one rule behind mesh welding
// (loadMeshFile), body vertices (the URDF scene) and the closed-mesh check.
#pragma once

#include <cstdint>
#include <vector>

#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
namespace detail
{
/// Points grouped by position: two points share a position when their
/// coordinates are bitwise identical, except that +0 and -0 are the same
/// (a NaN coordinate matches nothing). Positions are numbered in the order
/// of their first point.
struct IdenticalPositions
{
  std::vector<std::uint32_t> position_of;  ///< per point: the number of its position
  std::vector<Eigen::Index> first_point;   ///< per position: its first point
};

IdenticalPositions joinIdenticalPositions(const Matrix3X<double>& points);
}  // namespace detail
}  // namespace diff_rigid_body
