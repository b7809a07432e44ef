// Triangle meshes for tests, without the library's loader: a mesh from
// vertex and triangle lists, and a minimal Wavefront OBJ reader (an
// independent path to the same numbers that assimp gives the library).
#pragma once

#include <array>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/mass/triangle_mesh.h"

namespace drb_test
{
inline diff_rigid_body::TriangleMesh makeMesh(const std::vector<Eigen::Vector3d>& vertices,
                                              const std::vector<std::array<std::uint32_t, 3>>& triangles)
{
  diff_rigid_body::TriangleMesh mesh;
  mesh.vertices.resize(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t i = 0; i < vertices.size(); ++i)
    mesh.vertices.col(static_cast<Eigen::Index>(i)) = vertices[i];
  mesh.triangles = triangles;
  return mesh;
}

/// `v x y z` and `f a b c ...` lines (corners a, a/b, a//c or a/b/c; negative
/// indices count back from the last vertex); polygons are fanned from their
/// first corner. False, with the reason in *error when given, if the file
/// cannot be opened or has no vertex or no face.
inline bool readObj(const std::string& path, diff_rigid_body::TriangleMesh* mesh, std::string* error = nullptr)
{
  std::ifstream in(path);
  if (!in)
  {
    if (error)
      *error = "cannot open " + path;
    return false;
  }
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<std::uint32_t, 3>> f;
  std::string line;
  while (std::getline(in, line))
  {
    std::istringstream tokens(line);
    std::string tag;
    tokens >> tag;
    if (tag == "v")
    {
      Eigen::Vector3d p;
      tokens >> p.x() >> p.y() >> p.z();
      v.push_back(p);
    }
    else if (tag == "f")
    {
      std::vector<std::uint32_t> polygon;
      std::string corner;
      while (tokens >> corner)
      {
        const long index = std::stol(corner.substr(0, corner.find('/')));
        polygon.push_back(static_cast<std::uint32_t>(index > 0 ? index - 1 : static_cast<long>(v.size()) + index));
      }
      for (std::size_t k = 2; k < polygon.size(); ++k)
        f.push_back({ polygon[0], polygon[k - 1], polygon[k] });
    }
  }
  if (v.empty() || f.empty())
  {
    if (error)
      *error = path + " has no vertices or faces";
    return false;
  }
  *mesh = makeMesh(v, f);
  return true;
}
}  // namespace drb_test
