// The geometry of URDF links for the scene builder (not installed): which
// elements a link uses, their triangle meshes (primitives tessellated, mesh
// files resolved and read once per file and scale) and their mass
// properties for a density.
#pragma once

#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <urdf_model/link.h>

#include "diff_rigid_body/mass/mass_property_checks.h"
#include "diff_rigid_body/mass/triangle_mesh.h"
#include "diff_rigid_body/parsers/urdf_scene.h"

namespace diff_rigid_body
{
namespace detail
{
/// One <collision> or <visual> geometry with its origin in the link frame.
using LinkGeometry = std::pair<Eigen::Isometry3d, const urdf::Geometry*>;

/// The link's chosen geometry elements (`source`, falling back to the other
/// kind when the link has none of it), in document order.
std::vector<LinkGeometry> linkGeometries(const urdf::Link& link, GeometrySource source);

/// Mesh file path of a URDF mesh URI: package://pkg/path (through
/// options.find_package), file://path, an absolute path, or a path relative
/// to options.base_directory. Throws MeshLoadError naming the link and URI.
std::string resolveMeshPath(const std::string& uri, const std::string& link_name, const SceneOptions& options);

/// Triangle meshes of geometry elements; each mesh file is read once per scale.
class GeometryMeshes
{
public:
  explicit GeometryMeshes(const SceneOptions& options) : options_(options) {}

  /// The geometry in its own frame. Throws SceneDescriptionError for a
  /// primitive size that is not finite and > 0 m, MeshLoadError for a mesh
  /// file that cannot be resolved or read (naming the link).
  TriangleMesh mesh(const urdf::Geometry& geometry, const std::string& link_name);

private:
  const TriangleMesh& meshFile(const urdf::Mesh& mesh, const std::string& link_name);

  const SceneOptions& options_;
  std::map<std::pair<std::string, std::array<double, 3>>, TriangleMesh> cache_;
};

/// Mass properties of one geometry element in its own frame, for a density
/// [kg/m^3] (`mesh`: its triangles, for a mesh element). Throws
/// InvalidInertiaError naming the link when they cannot be computed.
MassProperties geometryMassProperties(const urdf::Geometry& geometry, const TriangleMesh& mesh, double density,
                                      const std::string& link_name);
}  // namespace detail
}  // namespace diff_rigid_body
