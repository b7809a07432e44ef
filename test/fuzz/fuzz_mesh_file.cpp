// libFuzzer target: mesh file bytes -> loadMeshFile, the loader the node uses
// for every <mesh filename> of a URDF (assimp, then scale and joining).
//
// Input: byte 0 picks the file's extension (STL, OBJ or Collada, the formats
// robot descriptions use: assimp chooses its importer by extension first,
// then by content), byte 1 the scale; the rest is the file. PLY is left out:
// assimp 5.2's ASCII PLY reader loops forever on some malformed headers
// (test/meshes/hostile/assimp_ply_ascii_hang.ply, docs/robustness.md). The
// file is written to a private temporary file and loaded from there, as a
// URDF's mesh would be.
//
// Passes when loading either throws a diff_rigid_body::Error (MeshLoadError
// for what assimp or the checks refuse) or gives a mesh with finite
// vertices, at least one triangle, and triangle indices in range with three
// distinct corners. Anything else (a crash or sanitizer report in our code or
// assimp's, another exception, a hang past -timeout) is a finding.

#include <cstdint>
#include <cstdio>
#include <string>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mesh_loader.h"
#include "fuzz_invariants.h"

namespace
{
namespace drb = diff_rigid_body;

const char* const kExtensions[] = { ".stl", ".obj", ".dae" };

// One scale per selector: identity, mirrored, tiny, anisotropic.
Eigen::Vector3d scaleFor(std::uint8_t selector)
{
  switch (selector % 4)
  {
    case 1:
      return Eigen::Vector3d(-1.0, 1.0, 1.0);
    case 2:
      return Eigen::Vector3d::Constant(1e-3);
    case 3:
      return Eigen::Vector3d(2.0, 0.5, 1.0);
    default:
      return Eigen::Vector3d::Ones();
  }
}

void requireValidMesh(const drb::TriangleMesh& mesh)
{
  drb_fuzz::require(mesh.vertices.allFinite(), "loaded mesh has non-finite vertices");
  drb_fuzz::require(!mesh.triangles.empty(), "loaded mesh has no triangle");
  const auto count = static_cast<std::uint32_t>(mesh.vertices.cols());
  for (const auto& t : mesh.triangles)
  {
    drb_fuzz::require(t[0] < count && t[1] < count && t[2] < count, "triangle index out of range");
    drb_fuzz::require(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "degenerate triangle kept");
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  if (size < 2)
    return 0;
  // In the working folder, which scripts/fuzz makes per run: the same path in every run.
  const std::string path = std::string("drb_fuzz_mesh") + kExtensions[data[0] % 3];
  {
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file)
      return 0;
    std::fwrite(data + 2, 1, size - 2, file);
    std::fclose(file);
  }
  try
  {
    requireValidMesh(drb::loadMeshFile(path, scaleFor(data[1])));
  }
  catch (const drb::Error&)
  {
    // refused with a message naming the file: fine
  }
  std::remove(path.c_str());
  return 0;
}
