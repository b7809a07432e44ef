// Mass properties of a homogeneous solid bounded by a closed triangle mesh:
// the closed-mesh check and the exact polyhedral volume integrals
// (mass_properties.h).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mass_properties.h"
#include "mass/identical_positions.h"
#include "value_checks.h"

namespace diff_rigid_body
{
namespace
{
using detail::formatVector;

/// |V| <= kZeroVolumeFactor DBL_EPSILON sum_t |V_t| counts as no volume at all.
constexpr double kZeroVolumeFactor = 64.0;

/// Throws MeshLoadError unless the mesh has vertices and triangles, every
/// vertex is finite and every index is in range.
void checkMeshElements(const TriangleMesh& mesh, const std::string& where)
{
  const std::size_t num_vertices = static_cast<std::size_t>(mesh.vertices.cols());
  if (num_vertices == 0)
    throw MeshLoadError(where + ": mesh has no vertices");
  if (mesh.triangles.empty())
    throw MeshLoadError(where + ": mesh has no triangles");
  for (std::size_t i = 0; i < num_vertices; ++i)
  {
    if (!mesh.vertices.col(i).allFinite())
      throw MeshLoadError(where + ": vertex " + std::to_string(i) + " is not finite " +
                          formatVector(mesh.vertices.col(i)));
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
  {
    for (std::uint32_t index : mesh.triangles[t])
    {
      if (index >= num_vertices)
        throw MeshLoadError(where + ": triangle " + std::to_string(t) + " refers to vertex " + std::to_string(index) +
                            " but the mesh has " + std::to_string(num_vertices) + " vertices");
    }
  }
}

/// The boundary chain of the mesh after welding: each undirected edge
/// {u < v} of welded vertices with its net use, +1 per use u -> v and -1 per
/// use v -> u. `welded[i]` is the first vertex at i's position. Sorted by edge.
std::vector<std::pair<std::uint64_t, int>> directedEdgeUses(const TriangleMesh& mesh,
                                                            const std::vector<std::uint32_t>& welded)
{
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& triangle : mesh.triangles)
  {
    for (int e = 0; e < 3; ++e)
    {
      const std::uint32_t u = welded[triangle[e]];
      const std::uint32_t v = welded[triangle[(e + 1) % 3]];
      if (u == v)
        continue;
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(u, v)) << 32) | std::max(u, v);
      edges.emplace_back(key, u < v ? 1 : -1);
    }
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

/// Edges whose uses do not cancel: how many, out of how many edges, and the first.
struct UnmatchedEdges
{
  std::size_t unmatched = 0;
  std::size_t edges = 0;
  std::uint64_t first_key = 0;
  int first_excess = 0;
};

UnmatchedEdges unmatchedEdges(const std::vector<std::pair<std::uint64_t, int>>& uses)
{
  UnmatchedEdges result;
  for (std::size_t i = 0; i < uses.size();)
  {
    std::size_t j = i;
    int net = 0;
    while (j < uses.size() && uses[j].first == uses[i].first)
      net += uses[j++].second;
    ++result.edges;
    if (net != 0)
    {
      if (result.unmatched == 0)
      {
        result.first_key = uses[i].first;
        result.first_excess = net;
      }
      ++result.unmatched;
    }
    i = j;
  }
  return result;
}
}  // namespace

void validateClosedMesh(const TriangleMesh& mesh, const std::string& where)
{
  checkMeshElements(mesh, where);
  const detail::IdenticalPositions positions = detail::joinIdenticalPositions(mesh.vertices);
  std::vector<std::uint32_t> welded(positions.position_of.size());
  for (std::size_t i = 0; i < welded.size(); ++i)
    welded[i] = static_cast<std::uint32_t>(positions.first_point[positions.position_of[i]]);
  const UnmatchedEdges open = unmatchedEdges(directedEdgeUses(mesh, welded));
  if (open.unmatched == 0)
    return;
  const std::uint32_t u = static_cast<std::uint32_t>(open.first_key >> 32);
  const std::uint32_t v = static_cast<std::uint32_t>(open.first_key & 0xffffffffu);
  std::ostringstream why;
  why << where << ": mesh is not closed and consistently oriented: " << open.unmatched << " of " << open.edges
      << " edges are unmatched, e.g. the edge between vertex " << u << " " << formatVector(mesh.vertices.col(u))
      << " and vertex " << v << " " << formatVector(mesh.vertices.col(v)) << " is used " << std::abs(open.first_excess)
      << " more time(s) in one direction than in the other (a hole, an open boundary or flipped triangles)";
  throw MeshLoadError(why.str());
}

MeshVolumeIntegrals meshVolumeIntegrals(const TriangleMesh& mesh, const std::string& where)
{
  validateClosedMesh(mesh, where);
  const Eigen::Vector3d reference = mesh.vertices.rowwise().mean();
  double six_volume = 0.0;          // sum 6 V_t
  double six_volume_abs = 0.0;      // sum 6 |V_t|
  Eigen::Vector3d first = Eigen::Vector3d::Zero();   // sum 24 F_t
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();  // sum 120 S_t
  for (const auto& triangle : mesh.triangles)
  {
    const Eigen::Vector3d a = mesh.vertices.col(triangle[0]) - reference;
    const Eigen::Vector3d b = mesh.vertices.col(triangle[1]) - reference;
    const Eigen::Vector3d c = mesh.vertices.col(triangle[2]) - reference;
    const double v6 = a.dot(b.cross(c));
    const Eigen::Vector3d s = a + b + c;
    six_volume += v6;
    six_volume_abs += std::abs(v6);
    first += v6 * s;
    second += v6 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  if (!(std::abs(six_volume) > kZeroVolumeFactor * DBL_EPSILON * six_volume_abs))
  {
    std::ostringstream why;
    why.precision(17);
    why << where << ": closed mesh encloses no volume (V = " << six_volume / 6.0
        << " m^3, zero to rounding against sum |V_t| = " << six_volume_abs / 6.0
        << " m^3): it is degenerate, flat or its parts cancel";
    throw MeshLoadError(why.str());
  }
  const double orientation = six_volume > 0.0 ? 1.0 : -1.0;  // inward-oriented: flip every integral
  MeshVolumeIntegrals result;
  result.volume = orientation * six_volume / 6.0;
  const Eigen::Vector3d centroid_local = (orientation * first / 24.0) / result.volume;
  result.centroid = reference + centroid_local;
  result.second_moment = orientation * second / 120.0 -
                         result.volume * centroid_local * centroid_local.transpose();
  return result;
}

MassProperties meshMassProperties(double density, const TriangleMesh& mesh, const std::string& where)
{
  detail::checkPositiveFinite(where, "density", density, "kg/m^3");
  const MeshVolumeIntegrals integrals = meshVolumeIntegrals(mesh, where);
  MassProperties result;
  result.mass = density * integrals.volume;
  result.com = integrals.centroid;
  result.inertia = density * detail::inertiaFromSecondMoment(integrals.second_moment);
  validateMassProperties(where, result.mass, result.inertia);
  return result;
}

}  // namespace diff_rigid_body
