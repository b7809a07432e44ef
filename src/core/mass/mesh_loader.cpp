#include "diff_rigid_body/mass/mesh_loader.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstring>
#include <sstream>
#include <unordered_map>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "mass/child_process.h"
#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
/// Mesh files over this size are refused before they are read [bytes].
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t(1) << 30;
/// At most this many triangle corners from one file (2^24 triangles).
constexpr std::size_t kMaxMeshCorners = std::size_t(3) << 24;
/// A read that takes longer is abandoned (its child process killed).
constexpr std::chrono::milliseconds kMeshReadTimeout{ 60000 };
/// Memory the reading child may allocate beyond the parent's [bytes].
constexpr std::size_t kMeshReadMemory = std::size_t(4) << 30;

// Appends the triangles of `node` and its children, in node order, placed by
// the accumulated node transform.
void collectTriangles(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent_transform,
                      std::vector<Eigen::Vector3d>& corners)
{
  const aiMatrix4x4 transform = parent_transform * node.mTransformation;
  for (unsigned m = 0; m < node.mNumMeshes; ++m)
  {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[m]];
    for (unsigned f = 0; f < mesh.mNumFaces; ++f)
    {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3)
        continue;  // points and lines carry no surface
      for (unsigned c = 0; c < 3; ++c)
      {
        const aiVector3D v = transform * mesh.mVertices[face.mIndices[c]];
        corners.emplace_back(v.x, v.y, v.z);
      }
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c)
    collectTriangles(scene, *node.mChildren[c], transform, corners);
}
// The corners of every triangle of the file, 3 per triangle, in the file's
// units and axes (assimp; see loadMeshFile).
std::vector<Eigen::Vector3d> readTriangleCorners(const std::string& path)
{
  Assimp::Importer importer;
  // Keep only positions: normals, colours and texture coordinates would stop
  // assimp from joining vertices and are not needed.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                          aiComponent_COLORS | aiComponent_TEXCOORDS |
                                                          aiComponent_BONEWEIGHTS | aiComponent_MATERIALS);
  // Collada: place the mesh as rviz and MoveIt do, in the file's own axes
  // with its <unit> applied; assimp would otherwise rotate Z-up files into Y-up.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_RemoveComponent | aiProcess_Triangulate | aiProcess_SortByPType);
  if (!scene || !scene->mRootNode)
    throw MeshLoadError("mesh '" + path + "': cannot be read: " + importer.GetErrorString());
  std::vector<Eigen::Vector3d> corners;
  collectTriangles(*scene, *scene->mRootNode, aiMatrix4x4(), corners);
  return corners;
}

// readTriangleCorners in a child process (src/core/mass/child_process.h): assimp's
// importers can crash, loop or allocate without bound on malformed files
// (docs/robustness.md, M rows); that refuses the file instead of ending the
// caller's process. The corners come back as raw doubles.
std::vector<Eigen::Vector3d> readTriangleCornersIsolated(const std::string& path)
{
  std::error_code error;
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  if (!error && bytes > kMaxMeshFileBytes)
    throw MeshLoadError("mesh '" + path + "': file of " + std::to_string(bytes) + " bytes is over the limit of " +
                        std::to_string(kMaxMeshFileBytes) + " bytes");
  std::string bytes_of_corners;
  try
  {
    bytes_of_corners = runInChildProcess(
        [&path] {
          const std::vector<Eigen::Vector3d> corners = readTriangleCorners(path);
          if (corners.size() > kMaxMeshCorners)
            throw MeshLoadError("mesh '" + path + "': " + std::to_string(corners.size() / 3) +
                                " triangles, over the limit of " + std::to_string(kMaxMeshCorners / 3));
          return std::string(reinterpret_cast<const char*>(corners.data()), corners.size() * sizeof(Eigen::Vector3d));
        },
        kMeshReadTimeout, kMeshReadMemory);
  }
  catch (const ChildProcessFailure& e)
  {
    throw MeshLoadError("mesh '" + path + "': assimp's reader " + e.what() + "; the file is malformed or too large");
  }
  catch (const std::runtime_error& e)  // what readTriangleCorners threw, by message
  {
    throw MeshLoadError(e.what());
  }
  std::vector<Eigen::Vector3d> corners(bytes_of_corners.size() / sizeof(Eigen::Vector3d));
  if (!corners.empty())
    std::memcpy(static_cast<void*>(corners.data()), bytes_of_corners.data(), corners.size() * sizeof(Eigen::Vector3d));
  return corners;
}
}  // namespace

TriangleMesh loadMeshFile(const std::string& path, const Eigen::Vector3d& scale)
{
  if (!scale.allFinite() || (scale.array() == 0.0).any())
  {
    std::ostringstream why;
    why << "mesh '" << path << "': scale must be finite and non-zero in every axis, got (" << scale.transpose()
        << ")";
    throw MeshLoadError(why.str());
  }
  const std::vector<Eigen::Vector3d> corners = readTriangleCornersIsolated(path);
  if (corners.empty())
    throw MeshLoadError("mesh '" + path + "': has no triangles");

  TriangleMesh soup;
  soup.vertices.resize(3, static_cast<Eigen::Index>(corners.size()));
  const bool mirrored = (scale.array() < 0.0).count() % 2 == 1;
  for (std::size_t i = 0; i < corners.size(); ++i)
    soup.vertices.col(static_cast<Eigen::Index>(i)) = corners[i].cwiseProduct(scale);
  for (std::uint32_t t = 0; t < corners.size() / 3; ++t)
  {
    if (mirrored)
      soup.triangles.push_back({ 3 * t, 3 * t + 2, 3 * t + 1 });
    else
      soup.triangles.push_back({ 3 * t, 3 * t + 1, 3 * t + 2 });
  }
  TriangleMesh mesh = joinIdenticalVertices(soup);
  if (!mesh.vertices.allFinite())
    throw MeshLoadError("mesh '" + path + "': has non-finite vertex coordinates");
  if (mesh.triangles.empty())
    throw MeshLoadError("mesh '" + path + "': all triangles are degenerate");
  return mesh;
}

TriangleMesh boxMesh(const Eigen::Vector3d& size)
{
  const Eigen::Vector3d h = 0.5 * size;
  TriangleMesh mesh;
  mesh.vertices.resize(3, 8);
  for (int i = 0; i < 8; ++i)
    mesh.vertices.col(i) << ((i & 1) ? h.x() : -h.x()), ((i & 2) ? h.y() : -h.y()), ((i & 4) ? h.z() : -h.z());
  // Outward (counter-clockwise seen from outside) faces: -z, +z, -y, +y, -x, +x.
  mesh.triangles = { { 0, 2, 1 }, { 1, 2, 3 }, { 4, 5, 6 }, { 5, 7, 6 }, { 0, 1, 4 }, { 1, 5, 4 },
                     { 2, 6, 3 }, { 3, 6, 7 }, { 0, 4, 2 }, { 2, 4, 6 }, { 1, 3, 5 }, { 3, 7, 5 } };
  return mesh;
}

TriangleMesh sphereMesh(double radius)
{
  constexpr int rings = PrimitiveResolution::kSphereRings;
  constexpr int segments = PrimitiveResolution::kSphereSegments;
  TriangleMesh mesh;
  mesh.vertices.resize(3, 2 + (rings - 1) * segments);
  Eigen::Index n = 0;
  mesh.vertices.col(n++) << 0.0, 0.0, radius;
  for (int ring = 1; ring < rings; ++ring)
  {
    const double polar = kPi * ring / rings;
    for (int s = 0; s < segments; ++s)
    {
      const double azimuth = 2.0 * kPi * s / segments;
      mesh.vertices.col(n++) << radius * std::sin(polar) * std::cos(azimuth),
          radius * std::sin(polar) * std::sin(azimuth), radius * std::cos(polar);
    }
  }
  const std::uint32_t south = static_cast<std::uint32_t>(n);
  mesh.vertices.col(n++) << 0.0, 0.0, -radius;
  auto ring_vertex = [](int ring, int s) {
    return static_cast<std::uint32_t>(1 + (ring - 1) * segments + (s % segments));
  };
  for (int s = 0; s < segments; ++s)
  {
    mesh.triangles.push_back({ 0, ring_vertex(1, s), ring_vertex(1, s + 1) });
    for (int ring = 1; ring < rings - 1; ++ring)
    {
      mesh.triangles.push_back({ ring_vertex(ring, s), ring_vertex(ring + 1, s), ring_vertex(ring + 1, s + 1) });
      mesh.triangles.push_back({ ring_vertex(ring, s), ring_vertex(ring + 1, s + 1), ring_vertex(ring, s + 1) });
    }
    mesh.triangles.push_back({ south, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s) });
  }
  return mesh;
}

TriangleMesh cylinderMesh(double radius, double length)
{
  constexpr int segments = PrimitiveResolution::kCylinderSegments;
  TriangleMesh mesh;
  mesh.vertices.resize(3, 2 * segments);
  for (int rim = 0; rim < 2; ++rim)
    for (int s = 0; s < segments; ++s)
    {
      const double azimuth = 2.0 * kPi * s / segments;
      mesh.vertices.col(rim * segments + s) << radius * std::cos(azimuth), radius * std::sin(azimuth),
          (rim == 0 ? -0.5 : 0.5) * length;
    }
  auto bottom = [](int s) { return static_cast<std::uint32_t>(s % segments); };
  auto top = [](int s) { return static_cast<std::uint32_t>(segments + s % segments); };
  for (int s = 0; s < segments; ++s)
  {
    mesh.triangles.push_back({ bottom(s), bottom(s + 1), top(s + 1) });
    mesh.triangles.push_back({ bottom(s), top(s + 1), top(s) });
  }
  for (int s = 1; s + 1 < segments; ++s)
  {
    mesh.triangles.push_back({ bottom(0), bottom(s + 1), bottom(s) });  // faces -z
    mesh.triangles.push_back({ top(0), top(s), top(s + 1) });           // faces +z
  }
  return mesh;
}

}  // namespace diff_rigid_body
