#include "parsers/link_geometry.h"

#include <cmath>
#include <exception>
#include <filesystem>
#include <sstream>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mass_properties.h"
#include "diff_rigid_body/mass/mesh_loader.h"
#include "parsers/urdf_model.h"

namespace diff_rigid_body
{
namespace detail
{
std::vector<LinkGeometry> linkGeometries(const urdf::Link& link, GeometrySource source)
{
  std::vector<LinkGeometry> collisions, visuals;
  for (const auto& c : link.collision_array)
    if (c && c->geometry)
      collisions.emplace_back(toIsometry(c->origin), c->geometry.get());
  for (const auto& v : link.visual_array)
    if (v && v->geometry)
      visuals.emplace_back(toIsometry(v->origin), v->geometry.get());
  if (source == GeometrySource::Collision)
    return collisions.empty() ? visuals : collisions;
  return visuals.empty() ? collisions : visuals;
}

std::string resolveMeshPath(const std::string& uri, const std::string& link_name, const SceneOptions& options)
{
  const std::string package_scheme = "package://";
  const std::string file_scheme = "file://";
  if (uri.rfind(package_scheme, 0) == 0)
  {
    const std::string rest = uri.substr(package_scheme.size());
    const std::size_t slash = rest.find('/');
    const std::string package = rest.substr(0, slash);
    std::string root, reason;
    if (options.find_package)
    {
      try
      {
        root = options.find_package(package);
      }
      catch (const std::exception& e)
      {
        root.clear();
        reason = e.what();
      }
    }
    if (root.empty())
      throw MeshLoadError("link '" + link_name + "': mesh '" + uri + "': cannot find package '" + package + "'" +
                          (reason.empty() ? "" : ": " + reason));
    const std::string inside = slash == std::string::npos ? "" : rest.substr(slash);
    // A package:// URI names a file inside the package: '..' may not leave it.
    const std::filesystem::path normal = std::filesystem::path("." + inside).lexically_normal();
    if (!normal.empty() && *normal.begin() == "..")
      throw MeshLoadError("link '" + link_name + "': mesh '" + uri + "': the path leaves package '" + package +
                          "' through '..'");
    return root + inside;
  }
  if (uri.rfind(file_scheme, 0) == 0)
    return uri.substr(file_scheme.size());
  if (!uri.empty() && uri[0] == '/')
    return uri;
  if (!options.base_directory.empty())
    return options.base_directory + "/" + uri;
  throw MeshLoadError("link '" + link_name + "': mesh '" + uri +
                      "': relative path with no base folder (use package://, file:// or an absolute path)");
}

const TriangleMesh& GeometryMeshes::meshFile(const urdf::Mesh& mesh, const std::string& link_name)
{
  const std::string path = resolveMeshPath(mesh.filename, link_name, options_);
  // The URI as written in the URDF; the loader's messages name the file it resolved to.
  const std::string written = "link '" + link_name + "': " +
                              (path == mesh.filename ? std::string() : "mesh '" + mesh.filename + "': ");
  const Eigen::Vector3d scale(mesh.scale.x, mesh.scale.y, mesh.scale.z);
  const auto key = std::make_pair(path, std::array<double, 3>{ scale.x(), scale.y(), scale.z() });
  auto found = cache_.find(key);
  if (found == cache_.end())
  {
    std::error_code error;
    if (!std::filesystem::exists(path, error) && !error)  // an error (e.g. a symlink loop): the reader says
      throw MeshLoadError(written + "mesh '" + path + "': no such file");
    try
    {
      found = cache_.emplace(key, loadMeshFile(path, scale)).first;
    }
    catch (const MeshLoadError& e)
    {
      throw MeshLoadError(written + e.what());
    }
  }
  return found->second;
}

TriangleMesh GeometryMeshes::mesh(const urdf::Geometry& geometry, const std::string& link_name)
{
  // A primitive size must be finite and > 0 [m].
  auto require_size = [&link_name](const char* what, double value) {
    if (!(std::isfinite(value) && value > 0.0))
    {
      std::ostringstream why;
      why << "link '" << link_name << "': " << what << " must be finite and > 0 m, got " << value;
      throw SceneDescriptionError(why.str());
    }
  };
  switch (geometry.type)
  {
    case urdf::Geometry::BOX:
    {
      const auto& box = static_cast<const urdf::Box&>(geometry);
      require_size("box size x", box.dim.x);
      require_size("box size y", box.dim.y);
      require_size("box size z", box.dim.z);
      return boxMesh(Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z));
    }
    case urdf::Geometry::SPHERE:
      require_size("sphere radius", static_cast<const urdf::Sphere&>(geometry).radius);
      return sphereMesh(static_cast<const urdf::Sphere&>(geometry).radius);
    case urdf::Geometry::CYLINDER:
    {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
      require_size("cylinder radius", cylinder.radius);
      require_size("cylinder length", cylinder.length);
      return cylinderMesh(cylinder.radius, cylinder.length);
    }
    case urdf::Geometry::MESH:
      return meshFile(static_cast<const urdf::Mesh&>(geometry), link_name);
  }
  throw SceneDescriptionError("link '" + link_name + "': unknown geometry type");
}

MassProperties geometryMassProperties(const urdf::Geometry& geometry, const TriangleMesh& mesh, double density,
                                      const std::string& link_name)
{
  try
  {
    switch (geometry.type)
    {
      case urdf::Geometry::BOX:
      {
        const auto& box = static_cast<const urdf::Box&>(geometry);
        return boxMassProperties(density, Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z));
      }
      case urdf::Geometry::SPHERE:
        return sphereMassProperties(density, static_cast<const urdf::Sphere&>(geometry).radius);
      case urdf::Geometry::CYLINDER:
      {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
        return cylinderMassProperties(density, cylinder.radius, cylinder.length);
      }
      default:
        return meshMassProperties(density, mesh);
    }
  }
  catch (const Error& e)
  {
    throw InvalidInertiaError("link '" + link_name + "': cannot compute inertia from its geometry: " + e.what());
  }
}
}  // namespace detail
}  // namespace diff_rigid_body
