#include "mass/identical_positions.h"

#include <cstring>
#include <functional>
#include <unordered_map>

#include "diff_rigid_body/mass/mesh_loader.h"

namespace diff_rigid_body
{
namespace
{
struct PositionHash
{
  std::size_t operator()(const Eigen::Vector3d& p) const
  {
    std::size_t seed = 0;
    for (int i = 0; i < 3; ++i)
    {
      double value = p[i] == 0.0 ? 0.0 : p[i];  // +0 and -0 are the same position
      std::uint64_t bits;
      std::memcpy(&bits, &value, sizeof bits);
      seed ^= std::hash<std::uint64_t>()(bits) + 0x9e3779b97f4a7c15ULL + (seed << 6) + (seed >> 2);
    }
    return seed;
  }
};

struct PositionEqual
{
  bool operator()(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const { return (a.array() == b.array()).all(); }
};
}  // namespace

namespace detail
{
IdenticalPositions joinIdenticalPositions(const Matrix3X<double>& points)
{
  IdenticalPositions joined;
  std::unordered_map<Eigen::Vector3d, std::uint32_t, PositionHash, PositionEqual> number_of;
  number_of.reserve(static_cast<std::size_t>(points.cols()));
  joined.position_of.resize(static_cast<std::size_t>(points.cols()));
  for (Eigen::Index v = 0; v < points.cols(); ++v)
  {
    const auto inserted = number_of.emplace(points.col(v), static_cast<std::uint32_t>(joined.first_point.size()));
    if (inserted.second)
      joined.first_point.push_back(v);
    joined.position_of[static_cast<std::size_t>(v)] = inserted.first->second;
  }
  return joined;
}
}  // namespace detail

TriangleMesh joinIdenticalVertices(const TriangleMesh& mesh)
{
  const detail::IdenticalPositions positions = detail::joinIdenticalPositions(mesh.vertices);
  const std::vector<std::uint32_t>& remap = positions.position_of;
  TriangleMesh joined;
  joined.vertices.resize(3, static_cast<Eigen::Index>(positions.first_point.size()));
  for (std::size_t i = 0; i < positions.first_point.size(); ++i)
    joined.vertices.col(static_cast<Eigen::Index>(i)) = mesh.vertices.col(positions.first_point[i]);
  joined.triangles.reserve(mesh.triangles.size());
  for (const auto& triangle : mesh.triangles)
  {
    const std::array<std::uint32_t, 3> t = { remap[triangle[0]], remap[triangle[1]], remap[triangle[2]] };
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
      joined.triangles.push_back(t);
  }
  return joined;
}

}  // namespace diff_rigid_body
