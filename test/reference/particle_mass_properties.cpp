#include "particle_mass_properties.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <vector>

#include "diff_rigid_body/exceptions.h"
#include "value_checks.h"

namespace diff_rigid_body
{
namespace
{
/// Grid offset of sample (0, 0, 0) from the bounding-box corner, in cells.
/// y and z are what the x-parallel rays see; their fractions are sqrt(2)-1
/// and sqrt(5)-2 scaled, so rays avoid the round coordinates that modelled
/// meshes tend to use.
const Eigen::Vector3d kGridOffset(0.5, 0.5 + 0.041421356237309505, 0.5 - 0.023606797749978970);

/// Limits on the particle grid (memory): rows of the (y, z) grid and
/// triangle-row bin entries.
constexpr long long kMaxGridRows = 1LL << 24;
constexpr long long kMaxBinEntries = 1LL << 26;

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

/// The sample grid, relative to the bounding-box centre (for accuracy far
/// from the origin): sample (i, j, k) at origin + h (i, j, k); rows (j, k)
/// of the (y, z) grid, row index k ny + j.
struct ParticleGrid
{
  double h = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> vertices;  ///< mesh vertices minus centre
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  long long ny = 0, nz = 0;
};

ParticleGrid makeGrid(const TriangleMesh& mesh, double h, const std::string& where, std::size_t target_samples)
{
  ParticleGrid grid;
  grid.h = h;
  grid.centre = 0.5 * (mesh.vertices.rowwise().minCoeff() + mesh.vertices.rowwise().maxCoeff());
  grid.vertices.resize(static_cast<std::size_t>(mesh.vertices.cols()));
  for (std::size_t i = 0; i < grid.vertices.size(); ++i)
    grid.vertices[i] = mesh.vertices.col(static_cast<Eigen::Index>(i)) - grid.centre;
  Eigen::Vector3d local_min = grid.vertices[0], local_max = grid.vertices[0];
  for (const Eigen::Vector3d& v : grid.vertices)
  {
    local_min = local_min.cwiseMin(v);
    local_max = local_max.cwiseMax(v);
  }
  grid.origin = local_min + h * kGridOffset;
  const double ny_real = std::floor((local_max.y() - grid.origin.y()) / h) + 1.0;
  const double nz_real = std::floor((local_max.z() - grid.origin.z()) / h) + 1.0;
  if (!(ny_real * nz_real <= static_cast<double>(kMaxGridRows)))
  {
    std::ostringstream why;
    why << where << ": particle grid of " << ny_real << " x " << nz_real << " rows (cell " << h
        << " m) exceeds the limit of " << kMaxGridRows << " rows; lower target_samples (" << target_samples << ")";
    throw InvalidArgumentError(why.str());
  }
  grid.ny = std::max(0LL, static_cast<long long>(ny_real));
  grid.nz = std::max(0LL, static_cast<long long>(nz_real));
  return grid;
}

/// Rows j0..j1 x k0..k1 that a triangle's (y, z) bounding box covers,
/// widened by one row on each side so that rounding never drops one.
struct RowRange
{
  long long j0, j1, k0, k1;
  bool empty() const { return j0 > j1 || k0 > k1; }
  long long size() const { return (j1 - j0 + 1) * (k1 - k0 + 1); }
};

RowRange rowRange(const ParticleGrid& grid, const std::array<std::uint32_t, 3>& triangle)
{
  const Eigen::Vector3d& a = grid.vertices[triangle[0]];
  const Eigen::Vector3d& b = grid.vertices[triangle[1]];
  const Eigen::Vector3d& c = grid.vertices[triangle[2]];
  const double h = grid.h;
  RowRange r;
  r.j0 = std::max(0LL, static_cast<long long>(std::ceil((std::min({ a.y(), b.y(), c.y() }) - grid.origin.y()) / h)) - 1);
  r.j1 = std::min(grid.ny - 1,
                  static_cast<long long>(std::floor((std::max({ a.y(), b.y(), c.y() }) - grid.origin.y()) / h)) + 1);
  r.k0 = std::max(0LL, static_cast<long long>(std::ceil((std::min({ a.z(), b.z(), c.z() }) - grid.origin.z()) / h)) - 1);
  r.k1 = std::min(grid.nz - 1,
                  static_cast<long long>(std::floor((std::max({ a.z(), b.z(), c.z() }) - grid.origin.z()) / h)) + 1);
  return r;
}

/// Triangles binned by row (compressed rows): row r's triangles are
/// triangles[start[r] .. start[r + 1]).
struct RowBins
{
  std::vector<std::uint64_t> start;
  std::vector<std::uint32_t> triangles;
};

RowBins binTriangles(const ParticleGrid& grid, const TriangleMesh& mesh, const std::string& where,
                     std::size_t target_samples)
{
  const std::size_t num_rows = static_cast<std::size_t>(grid.ny * grid.nz);
  std::vector<RowRange> ranges(mesh.triangles.size());
  RowBins bins;
  bins.start.assign(num_rows + 1, 0);
  long long num_entries = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
  {
    const RowRange& r = ranges[t] = rowRange(grid, mesh.triangles[t]);
    if (r.empty())
      continue;
    num_entries += r.size();
    if (num_entries > kMaxBinEntries)
    {
      std::ostringstream why;
      why << where << ": particle grid (cell " << grid.h << " m) needs more than " << kMaxBinEntries
          << " triangle-row entries; lower target_samples (" << target_samples << ")";
      throw InvalidArgumentError(why.str());
    }
    for (long long k = r.k0; k <= r.k1; ++k)
      for (long long j = r.j0; j <= r.j1; ++j)
        ++bins.start[static_cast<std::size_t>(k * grid.ny + j) + 1];
  }
  for (std::size_t row = 0; row < num_rows; ++row)
    bins.start[row + 1] += bins.start[row];
  bins.triangles.resize(static_cast<std::size_t>(num_entries));
  std::vector<std::uint64_t> fill(bins.start.begin(), bins.start.end() - 1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
  {
    const RowRange& r = ranges[t];
    if (r.empty())
      continue;
    for (long long k = r.k0; k <= r.k1; ++k)
      for (long long j = r.j0; j <= r.j1; ++j)
        bins.triangles[fill[static_cast<std::size_t>(k * grid.ny + j)]++] = static_cast<std::uint32_t>(t);
  }
  return bins;
}

/// Adds the samples x = origin_x + i h of the row (y, z) that lie inside
/// [x_enter, x_exit) of each inside interval of the sorted crossings
/// (non-zero winding rule: entering an outward mesh has direction -1).
void addRowSamples(const ParticleGrid& grid, double y, double z, const std::vector<RayCrossing>& crossings,
                   PointMoments& moments)
{
  const double h = grid.h;
  int winding = 0;
  double enter = 0.0;
  for (const RayCrossing& crossing : crossings)
  {
    const int before = winding;
    winding -= crossing.direction;
    if (before == 0 && winding != 0)
    {
      enter = crossing.x;
    }
    else if (before != 0 && winding == 0)
    {
      const double i0 = std::ceil((enter - grid.origin.x()) / h);
      const double i1 = std::ceil((crossing.x - grid.origin.x()) / h) - 1.0;
      const double n = i1 - i0 + 1.0;
      if (n < 1.0)
        continue;
      // A run of n collinear samples: mean at the middle one, and
      // sum (x - mean)^2 = h^2 n (n^2 - 1) / 12.
      const Eigen::Vector3d run_mean(grid.origin.x() + 0.5 * (i0 + i1) * h, y, z);
      Eigen::Matrix3d run_second_moment = Eigen::Matrix3d::Zero();
      run_second_moment(0, 0) = h * h * n * (n * n - 1.0) / 12.0;
      moments.merge(n, run_mean, run_second_moment);
    }
  }
}

/// Casts one ray per row and sums the samples inside the mesh.
PointMoments castRows(const ParticleGrid& grid, const TriangleMesh& mesh, const RowBins& bins)
{
  PointMoments moments;
  std::vector<RayCrossing> crossings;
  for (long long k = 0; k < grid.nz; ++k)
  {
    const double z = grid.origin.z() + static_cast<double>(k) * grid.h;
    for (long long j = 0; j < grid.ny; ++j)
    {
      const double y = grid.origin.y() + static_cast<double>(j) * grid.h;
      const std::size_t row = static_cast<std::size_t>(k * grid.ny + j);
      crossings.clear();
      for (std::uint64_t e = bins.start[row]; e < bins.start[row + 1]; ++e)
      {
        const auto& triangle = mesh.triangles[bins.triangles[e]];
        RayCrossing crossing;
        if (crossTriangle(grid.vertices[triangle[0]], grid.vertices[triangle[1]], grid.vertices[triangle[2]], y, z,
                          &crossing))
          crossings.push_back(crossing);
      }
      if (crossings.size() < 2)
        continue;
      std::sort(crossings.begin(), crossings.end(),
                [](const RayCrossing& a, const RayCrossing& b) { return a.x < b.x; });
      addRowSamples(grid, y, z, crossings, moments);
    }
  }
  return moments;
}
}  // namespace

ParticleMassProperties particleMassProperties(double density, const TriangleMesh& mesh, std::size_t target_samples,
                                              const std::string& where)
{
  detail::checkPositiveFinite(where, "density", density, "kg/m^3");
  if (target_samples == 0)
    throw InvalidArgumentError(where + ": target_samples must be > 0");
  const MeshVolumeIntegrals integrals = meshVolumeIntegrals(mesh, where);
  const double h = std::cbrt(integrals.volume / static_cast<double>(target_samples));
  const ParticleGrid grid = makeGrid(mesh, h, where, target_samples);
  const PointMoments moments = castRows(grid, mesh, binTriangles(grid, mesh, where, target_samples));
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
  result.grid_origin = grid.centre + grid.origin;
  result.mass_properties.mass = result.particle_mass * moments.count;
  result.mass_properties.com = grid.centre + moments.mean;
  result.mass_properties.inertia =
      detail::symmetrized(result.particle_mass * detail::inertiaFromSecondMoment(moments.second_moment));
  return result;
}

}  // namespace diff_rigid_body
