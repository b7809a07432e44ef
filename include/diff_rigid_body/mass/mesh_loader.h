// Geometry sources for body vertices: mesh files (through assimp) and the
// documented tessellation of URDF primitives.
#pragma once

#include <string>

#include <Eigen/Core>

#include "diff_rigid_body/mass/triangle_mesh.h"

namespace diff_rigid_body
{
/// Vertex resolution of tessellated primitives (part of the public contract).
struct PrimitiveResolution
{
  /// Sphere: a UV sphere with both poles plus (kSphereRings - 1) rings of
  /// kSphereSegments vertices: 2 + 7 * 16 = 114 vertices.
  static constexpr int kSphereRings = 8;
  static constexpr int kSphereSegments = 16;
  /// Cylinder: two rims of kCylinderSegments vertices each (64 vertices),
  /// caps triangulated as fans, no centre vertex.
  static constexpr int kCylinderSegments = 32;
};

/// Loads a triangle mesh through assimp (STL, OBJ, DAE, PLY, ...): all meshes
/// of the file, placed by their node transforms, triangulated, multiplied
/// componentwise by `scale`, with identical positions joined. Vertex order
/// ("mesh order") is the order of first use by the file's faces. A negative number of mirrored axes flips the winding.
/// Throws MeshLoadError naming the file when it is missing, unreadable, has
/// no triangles, or `scale` is zero or non-finite in any component.
TriangleMesh loadMeshFile(const std::string& path, const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

/// Joins vertices with bitwise-identical positions, keeping the first
/// occurrence order, and re-indexes the triangles; drops triangles that
/// become degenerate (two equal corners).
TriangleMesh joinIdenticalVertices(const TriangleMesh& mesh);

/// Box of edge lengths `size` [m] centred at the origin: its 8 corners,
/// x fastest: (-x,-y,-z), (+x,-y,-z), (-x,+y,-z), (+x,+y,-z), then +z.
TriangleMesh boxMesh(const Eigen::Vector3d& size);

/// UV sphere of `radius` [m] at the origin (PrimitiveResolution): north pole
/// (0,0,r) first, rings from north to south starting at +x, south pole last.
TriangleMesh sphereMesh(double radius);

/// Cylinder of `radius` and `length` [m] along z, centred at the origin:
/// the bottom rim (z = -length/2) then the top rim, each starting at +x,
/// counter-clockwise about +z.
TriangleMesh cylinderMesh(double radius, double length);

}  // namespace diff_rigid_body
