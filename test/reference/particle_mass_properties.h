// The seed paper's particle approximation of a mesh's mass properties,
// eq. (17), over grid samples inside a closed mesh. Reference code: the node
// computes mass properties exactly (meshMassProperties); tests and
// bench/bench_inertia.cpp compare the two. Conventions: mass_properties.h.
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Core>

#include "diff_rigid_body/mass/mass_properties.h"
#include "mesh_ray_casting.h"

namespace diff_rigid_body
{
/// Result of particleMassProperties.
struct ParticleMassProperties
{
  MassProperties mass_properties;  ///< eq. (17) over the samples, in the mesh frame
  std::size_t num_samples = 0;     ///< particles inside the mesh
  double cell_size = 0.0;          ///< grid spacing h [m]
  double particle_mass = 0.0;      ///< rho h^3 [kg]
  /// Position of grid sample (0, 0, 0) [m]: sample (i, j, k) is at
  /// grid_origin + h (i, j, k); every sample used has i, j, k >= 0.
  Eigen::Vector3d grid_origin = Eigen::Vector3d::Zero();
};

/// The seed paper's particle approximation, eq. (17):
///   m   = sum_i m_i,    com = (1/m) sum_i m_i p_i,
///   I'  = sum_i m_i (p_i^T p_i I3 - p_i p_i^T),  p_i measured from com,
/// with one particle of mass m_i = rho h^3 at every point of a regular grid
/// that lies inside the closed mesh. h = cbrt(V / target_samples), so about
/// target_samples points fall inside. The grid is offset from the bounding
/// box corner by irrational-looking fractions of h so that rays rarely meet
/// vertices or edges exactly.
///
/// Inside points are found by scanline ray casting: triangles are binned by
/// their (y, z) bounding box into grid rows; each row's x-parallel ray is
/// crossed with its triangles (crossTriangle), the crossings sorted, and the
/// samples between crossings of non-zero winding number are taken. Collinear
/// samples are summed in closed form (the same sum, evaluated per run) and
/// runs are merged with the parallel-axis theorem, so the cost is
/// O(triangles x rows each covers + rows log) and not O(samples).
///
/// Throws InvalidArgumentError for a density not finite and > 0, a
/// target_samples of 0, or a grid too large for memory (over 2^24 rows or
/// 2^26 triangle-row entries, e.g. a huge target on a long thin mesh);
/// MeshLoadError as meshVolumeIntegrals (the mesh must be closed);
/// InvalidArgumentError if no sample falls inside. The result is not
/// validated: a handful of samples may give a singular inertia.
ParticleMassProperties particleMassProperties(double density, const TriangleMesh& mesh, std::size_t target_samples,
                                              const std::string& where = "mesh");

}  // namespace diff_rigid_body
