// A closed (or open) triangle mesh: vertex positions plus index triples.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
struct TriangleMesh
{
  Matrix3X<double> vertices;                            ///< one per column [m]
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< counter-clockwise seen from outside
};

}  // namespace diff_rigid_body
