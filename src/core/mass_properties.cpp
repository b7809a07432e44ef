#include "diff_rigid_body/mass_properties.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>

#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace
{
constexpr double kPi = 3.14159265358979323846;

/// Deviation from orthonormality accepted in a pose's rotation, |R^T R - I|_max.
constexpr double kRotationOrthonormalityTolerance = 1e-9;

/// |V| <= kZeroVolumeFactor DBL_EPSILON sum_t |V_t| counts as no volume at all.
constexpr double kZeroVolumeFactor = 64.0;

/// Grid offset of sample (0, 0, 0) from the bounding-box corner, in cells.
/// y and z are what the x-parallel rays see; their fractions are sqrt(2)-1
/// and sqrt(5)-2 scaled, so rays avoid the round coordinates that modelled
/// meshes tend to use.
const Eigen::Vector3d kGridOffset(0.5, 0.5 + 0.041421356237309505, 0.5 - 0.023606797749978970);

/// Limits on the particle grid (memory): rows of the (y, z) grid and
/// triangle-row bin entries.
constexpr long long kMaxGridRows = 1LL << 24;
constexpr long long kMaxBinEntries = 1LL << 26;

std::string formatVector(const Eigen::Vector3d& v)
{
  std::ostringstream out;
  out.precision(17);
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

void checkPositiveFinite(const std::string& where, const char* name, double value, const char* unit)
{
  if (!std::isfinite(value) || !(value > 0.0))
  {
    std::ostringstream why;
    why.precision(17);
    why << where << ": " << name << " must be finite and > 0 " << unit << ", got " << value;
    throw InvalidArgumentError(why.str());
  }
}

Eigen::Matrix3d symmetrized(const Eigen::Matrix3d& m)
{
  return 0.5 * (m + m.transpose());
}

/// Inertia of a body with second moment C = integral rho x x^T dm about its COM:
/// I = tr(C) I3 - C.
Eigen::Matrix3d inertiaFromSecondMoment(const Eigen::Matrix3d& C)
{
  return C.trace() * Eigen::Matrix3d::Identity() - C;
}

// ---------------------------------------------------------------------------
// Ray casting for the particle grid. Rays run along +x at fixed (y, z).

/// Edge function of the directed edge a -> b at the ray (y, z), with the
/// sign the symbolically perturbed ray (y + e, z + e^2), e -> 0+, would give:
///   E = (b_y - a_y)(z - a_z) - (b_z - a_z)(y - a_y),
/// > 0 when the ray is left of a -> b in the (y, z) plane. It is evaluated
/// with the endpoints in a canonical order and negated when reversed, so the
/// two triangles sharing an edge see exactly opposite values and signs: a
/// ray through an edge or vertex is inside exactly one of them.
struct EdgeSide
{
  double value;  ///< E [m^2]
  int sign;      ///< sign of the perturbed E; 0 only for an edge parallel to x
};

EdgeSide edgeSide(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double y, double z)
{
  const bool reversed = (b.y() < a.y()) || (b.y() == a.y() && b.z() < a.z());
  const Eigen::Vector3d& p = reversed ? b : a;
  const Eigen::Vector3d& q = reversed ? a : b;
  const double dy = q.y() - p.y();
  const double dz = q.z() - p.z();
  const double value = dy * (z - p.z()) - dz * (y - p.y());
  int sign;
  if (value != 0.0)
    sign = value > 0.0 ? 1 : -1;
  else if (dz != 0.0)  // dE/dy = -dz
    sign = dz < 0.0 ? 1 : -1;
  else  // dE/dz = dy
    sign = dy > 0.0 ? 1 : (dy < 0.0 ? -1 : 0);
  return reversed ? EdgeSide{ -value, -sign } : EdgeSide{ value, sign };
}

struct Crossing
{
  double x;       ///< where the ray crosses the triangle [m]
  int direction;  ///< +1 when the triangle's normal has n_x > 0 (leaving an outward mesh), -1 otherwise
};

/// Crossing of the ray (y, z) with triangle (v0, v1, v2), if any. The x
/// coordinate is the barycentric combination with weights w_i = E of the
/// edge opposite v_i, clamped to the triangle's x range.
bool crossTriangle(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1, const Eigen::Vector3d& v2, double y,
                   double z, Crossing* crossing)
{
  const EdgeSide e0 = edgeSide(v1, v2, y, z);
  if (e0.sign == 0)
    return false;
  const EdgeSide e1 = edgeSide(v2, v0, y, z);
  if (e1.sign != e0.sign)
    return false;
  const EdgeSide e2 = edgeSide(v0, v1, y, z);
  if (e2.sign != e0.sign)
    return false;
  const double sum = e0.value + e1.value + e2.value;
  const double x_min = std::min({ v0.x(), v1.x(), v2.x() });
  const double x_max = std::max({ v0.x(), v1.x(), v2.x() });
  double x = (sum != 0.0) ? (e0.value * v0.x() + e1.value * v1.x() + e2.value * v2.x()) / sum :
                            (v0.x() + v1.x() + v2.x()) / 3.0;
  crossing->x = std::min(std::max(x, x_min), x_max);
  crossing->direction = e0.sign;
  return true;
}

/// Running count, mean and second moment about the mean of equal point
/// masses, merged group by group (Chan, Golub and LeVeque):
///   n = n_a + n_b,  d = mean_b - mean_a,
///   mean = mean_a + d n_b / n,  C = C_a + C_b + d d^T n_a n_b / n,
/// which is the parallel-axis theorem for unit masses.
struct PointMoments
{
  double count = 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();  ///< sum (p - mean)(p - mean)^T [m^2]

  void merge(double n, const Eigen::Vector3d& group_mean, const Eigen::Matrix3d& group_second_moment)
  {
    const double total = count + n;
    const Eigen::Vector3d d = group_mean - mean;
    mean += d * (n / total);
    second_moment += group_second_moment + d * d.transpose() * (count * n / total);
    count = total;
  }
};

}  // namespace

Eigen::Matrix3d pointMassInertia(double mass, const Eigen::Vector3d& offset)
{
  return mass * (offset.squaredNorm() * Eigen::Matrix3d::Identity() - offset * offset.transpose());
}

MassProperties transformMassProperties(const Eigen::Isometry3d& X_BA, const MassProperties& in_A)
{
  MassProperties in_B;
  in_B.mass = in_A.mass;
  in_B.com = X_BA * in_A.com;
  in_B.inertia = symmetrized(X_BA.linear() * in_A.inertia * X_BA.linear().transpose());
  return in_B;
}

MassProperties combineMassProperties(const std::vector<std::pair<Eigen::Isometry3d, MassProperties>>& parts,
                                     const std::string& where)
{
  if (parts.empty())
    throw InvalidInertiaError(where + ": no parts to combine");
  std::vector<MassProperties> in_target;
  in_target.reserve(parts.size());
  double mass = 0.0;
  Eigen::Vector3d weighted_com = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < parts.size(); ++k)
  {
    const Eigen::Isometry3d& pose = parts[k].first;
    const MassProperties& part = parts[k].second;
    std::ostringstream why;
    why.precision(17);
    why << where << ": part " << k << ": ";
    if (!pose.matrix().allFinite())
    {
      why << "pose must be finite";
      throw InvalidInertiaError(why.str());
    }
    const double non_orthonormality =
        (pose.linear().transpose() * pose.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (non_orthonormality > kRotationOrthonormalityTolerance)
    {
      why << "pose rotation is not orthonormal (|R^T R - I| = " << non_orthonormality << ")";
      throw InvalidInertiaError(why.str());
    }
    if (!std::isfinite(part.mass) || part.mass < 0.0)
    {
      why << "mass must be finite and >= 0 kg, got " << part.mass;
      throw InvalidInertiaError(why.str());
    }
    if (!part.com.allFinite())
    {
      why << "COM must be finite, got " << formatVector(part.com);
      throw InvalidInertiaError(why.str());
    }
    if (!part.inertia.allFinite())
    {
      why << "inertia must be finite";
      throw InvalidInertiaError(why.str());
    }
    in_target.push_back(transformMassProperties(pose, part));
    mass += part.mass;
    weighted_com += part.mass * in_target.back().com;
  }
  if (!(mass > 0.0) || !std::isfinite(mass))
  {
    std::ostringstream why;
    why.precision(17);
    why << where << ": total mass must be finite and > 0 kg, got " << mass;
    throw InvalidInertiaError(why.str());
  }
  MassProperties result;
  result.mass = mass;
  result.com = weighted_com / mass;
  for (const MassProperties& part : in_target)
    result.inertia += part.inertia + pointMassInertia(part.mass, part.com - result.com);
  result.inertia = symmetrized(result.inertia);
  return result;
}

MassProperties boxMassProperties(double density, const Eigen::Vector3d& size)
{
  checkPositiveFinite("box", "density", density, "kg/m^3");
  checkPositiveFinite("box", "size x", size.x(), "m");
  checkPositiveFinite("box", "size y", size.y(), "m");
  checkPositiveFinite("box", "size z", size.z(), "m");
  MassProperties result;
  result.mass = density * size.prod();
  const Eigen::Vector3d sq = size.cwiseAbs2();
  result.inertia.diagonal() << sq.y() + sq.z(), sq.x() + sq.z(), sq.x() + sq.y();
  result.inertia *= result.mass / 12.0;
  return result;
}

MassProperties sphereMassProperties(double density, double radius)
{
  checkPositiveFinite("sphere", "density", density, "kg/m^3");
  checkPositiveFinite("sphere", "radius", radius, "m");
  MassProperties result;
  result.mass = density * (4.0 / 3.0) * kPi * radius * radius * radius;
  result.inertia.diagonal().setConstant(0.4 * result.mass * radius * radius);
  return result;
}

MassProperties cylinderMassProperties(double density, double radius, double length)
{
  checkPositiveFinite("cylinder", "density", density, "kg/m^3");
  checkPositiveFinite("cylinder", "radius", radius, "m");
  checkPositiveFinite("cylinder", "length", length, "m");
  MassProperties result;
  result.mass = density * kPi * radius * radius * length;
  const double transverse = result.mass * (3.0 * radius * radius + length * length) / 12.0;
  result.inertia.diagonal() << transverse, transverse, 0.5 * result.mass * radius * radius;
  return result;
}

void validateClosedMesh(const TriangleMesh& mesh, const std::string& where)
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

  // Weld vertices at identical positions: welded[i] is the smallest index at i's position.
  std::vector<std::uint32_t> order(num_vertices);
  std::iota(order.begin(), order.end(), 0u);
  const auto less = [&mesh](std::uint32_t a, std::uint32_t b) {
    const auto pa = mesh.vertices.col(a);
    const auto pb = mesh.vertices.col(b);
    if (pa.x() != pb.x())
      return pa.x() < pb.x();
    if (pa.y() != pb.y())
      return pa.y() < pb.y();
    if (pa.z() != pb.z())
      return pa.z() < pb.z();
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> welded(num_vertices);
  for (std::size_t k = 0; k < num_vertices; ++k)
  {
    const bool same = k > 0 && mesh.vertices.col(order[k]) == mesh.vertices.col(order[k - 1]);
    welded[order[k]] = same ? welded[order[k - 1]] : order[k];
  }

  // The boundary chain: each undirected edge {u < v} gets +1 per use u -> v and -1 per use v -> u.
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
  std::size_t unmatched = 0;
  std::size_t num_edges = 0;
  std::uint64_t first_key = 0;
  int first_excess = 0;
  for (std::size_t i = 0; i < edges.size();)
  {
    std::size_t j = i;
    int net = 0;
    while (j < edges.size() && edges[j].first == edges[i].first)
      net += edges[j++].second;
    ++num_edges;
    if (net != 0)
    {
      if (unmatched == 0)
      {
        first_key = edges[i].first;
        first_excess = net;
      }
      ++unmatched;
    }
    i = j;
  }
  if (unmatched > 0)
  {
    const std::uint32_t u = static_cast<std::uint32_t>(first_key >> 32);
    const std::uint32_t v = static_cast<std::uint32_t>(first_key & 0xffffffffu);
    std::ostringstream why;
    why << where << ": mesh is not closed and consistently oriented: " << unmatched << " of " << num_edges
        << " edges are unmatched, e.g. the edge between vertex " << u << " " << formatVector(mesh.vertices.col(u))
        << " and vertex " << v << " " << formatVector(mesh.vertices.col(v)) << " is used " << std::abs(first_excess)
        << " more time(s) in one direction than in the other (a hole, an open boundary or flipped triangles)";
    throw MeshLoadError(why.str());
  }
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
  checkPositiveFinite(where, "density", density, "kg/m^3");
  const MeshVolumeIntegrals integrals = meshVolumeIntegrals(mesh, where);
  MassProperties result;
  result.mass = density * integrals.volume;
  result.com = integrals.centroid;
  result.inertia = density * inertiaFromSecondMoment(integrals.second_moment);
  validateMassProperties(where, result.mass, result.inertia);
  return result;
}

int meshWindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& point)
{
  if (!point.allFinite())
    throw InvalidArgumentError("meshWindingNumber: point must be finite, got " + formatVector(point));
  int winding = 0;
  for (const auto& triangle : mesh.triangles)
  {
    Crossing crossing;
    if (crossTriangle(mesh.vertices.col(triangle[0]), mesh.vertices.col(triangle[1]), mesh.vertices.col(triangle[2]),
                      point.y(), point.z(), &crossing) &&
        crossing.x > point.x())
      winding += crossing.direction;
  }
  return winding;
}

ParticleMassProperties particleMassProperties(double density, const TriangleMesh& mesh, std::size_t target_samples,
                                              const std::string& where)
{
  checkPositiveFinite(where, "density", density, "kg/m^3");
  if (target_samples == 0)
    throw InvalidArgumentError(where + ": target_samples must be > 0");
  const MeshVolumeIntegrals integrals = meshVolumeIntegrals(mesh, where);
  const double h = std::cbrt(integrals.volume / static_cast<double>(target_samples));

  // Work relative to the bounding-box centre, for accuracy far from the origin.
  const Eigen::Vector3d box_min = mesh.vertices.rowwise().minCoeff();
  const Eigen::Vector3d box_max = mesh.vertices.rowwise().maxCoeff();
  const Eigen::Vector3d centre = 0.5 * (box_min + box_max);
  const std::size_t num_vertices = static_cast<std::size_t>(mesh.vertices.cols());
  std::vector<Eigen::Vector3d> vertices(num_vertices);
  for (std::size_t i = 0; i < num_vertices; ++i)
    vertices[i] = mesh.vertices.col(i) - centre;
  Eigen::Vector3d local_min = vertices[0];
  Eigen::Vector3d local_max = vertices[0];
  for (const Eigen::Vector3d& v : vertices)
  {
    local_min = local_min.cwiseMin(v);
    local_max = local_max.cwiseMax(v);
  }
  const Eigen::Vector3d origin = local_min + h * kGridOffset;  // sample (0, 0, 0), local coordinates

  // Rows (j, k) of the (y, z) grid, at y = origin_y + j h, z = origin_z + k h.
  const double ny_real = std::floor((local_max.y() - origin.y()) / h) + 1.0;
  const double nz_real = std::floor((local_max.z() - origin.z()) / h) + 1.0;
  if (!(ny_real * nz_real <= static_cast<double>(kMaxGridRows)))
  {
    std::ostringstream why;
    why << where << ": particle grid of " << ny_real << " x " << nz_real << " rows (cell " << h
        << " m) exceeds the limit of " << kMaxGridRows << " rows; lower target_samples (" << target_samples << ")";
    throw InvalidArgumentError(why.str());
  }
  const long long ny = std::max(0LL, static_cast<long long>(ny_real));
  const long long nz = std::max(0LL, static_cast<long long>(nz_real));
  const long long num_rows = ny * nz;

  // Bin triangles into the rows their (y, z) bounding box covers, widened by
  // one row on each side so that rounding in the index never drops one.
  struct RowRange
  {
    long long j0, j1, k0, k1;
  };
  std::vector<RowRange> ranges(mesh.triangles.size());
  std::vector<std::uint64_t> row_start(static_cast<std::size_t>(num_rows) + 1, 0);
  long long num_entries = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
  {
    const Eigen::Vector3d& a = vertices[mesh.triangles[t][0]];
    const Eigen::Vector3d& b = vertices[mesh.triangles[t][1]];
    const Eigen::Vector3d& c = vertices[mesh.triangles[t][2]];
    RowRange& r = ranges[t];
    r.j0 = std::max(0LL, static_cast<long long>(std::ceil((std::min({ a.y(), b.y(), c.y() }) - origin.y()) / h)) - 1);
    r.j1 = std::min(ny - 1, static_cast<long long>(std::floor((std::max({ a.y(), b.y(), c.y() }) - origin.y()) / h)) + 1);
    r.k0 = std::max(0LL, static_cast<long long>(std::ceil((std::min({ a.z(), b.z(), c.z() }) - origin.z()) / h)) - 1);
    r.k1 = std::min(nz - 1, static_cast<long long>(std::floor((std::max({ a.z(), b.z(), c.z() }) - origin.z()) / h)) + 1);
    if (r.j0 > r.j1 || r.k0 > r.k1)
      continue;
    num_entries += (r.j1 - r.j0 + 1) * (r.k1 - r.k0 + 1);
    if (num_entries > kMaxBinEntries)
    {
      std::ostringstream why;
      why << where << ": particle grid (cell " << h << " m) needs more than " << kMaxBinEntries
          << " triangle-row entries; lower target_samples (" << target_samples << ")";
      throw InvalidArgumentError(why.str());
    }
    for (long long k = r.k0; k <= r.k1; ++k)
      for (long long j = r.j0; j <= r.j1; ++j)
        ++row_start[static_cast<std::size_t>(k * ny + j) + 1];
  }
  for (std::size_t row = 0; row < static_cast<std::size_t>(num_rows); ++row)
    row_start[row + 1] += row_start[row];
  std::vector<std::uint32_t> bins(static_cast<std::size_t>(num_entries));
  {
    std::vector<std::uint64_t> fill(row_start.begin(), row_start.end() - 1);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    {
      const RowRange& r = ranges[t];
      if (r.j0 > r.j1 || r.k0 > r.k1)
        continue;
      for (long long k = r.k0; k <= r.k1; ++k)
        for (long long j = r.j0; j <= r.j1; ++j)
          bins[fill[static_cast<std::size_t>(k * ny + j)]++] = static_cast<std::uint32_t>(t);
    }
  }

  // Cast one ray per row; take the samples x = origin_x + i h inside [x_enter, x_exit).
  PointMoments moments;
  std::vector<Crossing> crossings;
  for (long long k = 0; k < nz; ++k)
  {
    const double z = origin.z() + static_cast<double>(k) * h;
    for (long long j = 0; j < ny; ++j)
    {
      const double y = origin.y() + static_cast<double>(j) * h;
      const std::size_t row = static_cast<std::size_t>(k * ny + j);
      crossings.clear();
      for (std::uint64_t e = row_start[row]; e < row_start[row + 1]; ++e)
      {
        const auto& triangle = mesh.triangles[bins[e]];
        Crossing crossing;
        if (crossTriangle(vertices[triangle[0]], vertices[triangle[1]], vertices[triangle[2]], y, z, &crossing))
          crossings.push_back(crossing);
      }
      if (crossings.size() < 2)
        continue;
      std::sort(crossings.begin(), crossings.end(),
                [](const Crossing& a, const Crossing& b) { return a.x < b.x; });
      // Non-zero winding rule: entering an outward mesh has direction -1.
      int winding = 0;
      double enter = 0.0;
      for (const Crossing& crossing : crossings)
      {
        const int before = winding;
        winding -= crossing.direction;
        if (before == 0 && winding != 0)
        {
          enter = crossing.x;
        }
        else if (before != 0 && winding == 0)
        {
          const double i0 = std::ceil((enter - origin.x()) / h);
          const double i1 = std::ceil((crossing.x - origin.x()) / h) - 1.0;
          const double n = i1 - i0 + 1.0;
          if (n < 1.0)
            continue;
          // A run of n collinear samples: mean at the middle one, and
          // sum (x - mean)^2 = h^2 n (n^2 - 1) / 12.
          const Eigen::Vector3d run_mean(origin.x() + 0.5 * (i0 + i1) * h, y, z);
          Eigen::Matrix3d run_second_moment = Eigen::Matrix3d::Zero();
          run_second_moment(0, 0) = h * h * n * (n * n - 1.0) / 12.0;
          moments.merge(n, run_mean, run_second_moment);
        }
      }
    }
  }
  if (moments.count < 1.0)
  {
    std::ostringstream why;
    why << where << ": no particle-grid sample (cell " << h << " m) falls inside the mesh; raise target_samples ("
        << target_samples << ")";
    throw InvalidArgumentError(why.str());
  }

  ParticleMassProperties result;
  result.num_samples = static_cast<std::size_t>(moments.count);
  result.cell_size = h;
  result.particle_mass = density * h * h * h;
  result.grid_origin = centre + origin;
  result.mass_properties.mass = result.particle_mass * moments.count;
  result.mass_properties.com = centre + moments.mean;
  result.mass_properties.inertia =
      symmetrized(result.particle_mass * inertiaFromSecondMoment(moments.second_moment));
  return result;
}

}  // namespace diff_rigid_body
