// Rays along +x against a triangle mesh: the crossing test shared by the
// particle grid (particle_mass_properties.h) and the winding number.
// Reference code for tests and benchmarks; the node never runs it.
#pragma once

#include <Eigen/Core>

#include "diff_rigid_body/mass/triangle_mesh.h"

namespace diff_rigid_body
{
/// A crossing of a ray (y, z) along +x with a triangle.
struct RayCrossing
{
  double x;       ///< where the ray crosses the triangle [m]
  int direction;  ///< +1 when the triangle's normal has n_x > 0 (leaving an outward mesh), -1 otherwise
};

/// Crossing of the ray (y, z) with triangle (v0, v1, v2), if any. Edge
/// functions E = (b_y - a_y)(z - a_z) - (b_z - a_z)(y - a_y) of the three
/// edges are evaluated with the endpoints in a canonical order, so the two
/// triangles sharing an edge see exactly opposite values and signs, and ties
/// are broken as for the perturbed ray (y + e, z + e^2), e -> 0+: a ray
/// through an edge or vertex crosses exactly one of its triangles. The x
/// coordinate is the barycentric combination with weights w_i = E of the
/// edge opposite v_i, clamped to the triangle's x range.
bool crossTriangle(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1, const Eigen::Vector3d& v2, double y,
                   double z, RayCrossing* crossing);

/// Winding number of a closed mesh about a point, counted along the ray
/// from the point in +x with crossTriangle:
///   w = sum over crossings with x_c > point_x of (+1 if the triangle's
///       normal has n_x > 0, else -1),
/// so w = 1 inside an outward-oriented mesh, -1 inside an inward one and 0
/// outside. A crossing at x_c = point_x is not counted: a point on a face
/// parallel to x, an edge or a vertex still gets a consistent answer.
/// Precondition: validateClosedMesh(mesh) passed (not re-checked, O(T)).
/// Throws InvalidArgumentError for a non-finite point.
int meshWindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& point);

}  // namespace diff_rigid_body
