// Mesh files through assimp, vertex joining, and the documented primitive tessellation.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <array>
#include <map>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mesh_loader.h"
#include "../support/expect_throws.h"

namespace drb = diff_rigid_body;

namespace
{
constexpr double kLengthTolerance = 1e-12;  // m
const std::string kTestMeshDir = std::string(DRB_TEST_DATA_DIR) + "/meshes";

// Volume by the divergence theorem, sum over triangles of a . (b x c) / 6:
// positive for an outward-oriented closed mesh.
double signedVolume(const drb::TriangleMesh& mesh)
{
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
    volume += mesh.vertices.col(t[0]).dot(mesh.vertices.col(t[1]).cross(mesh.vertices.col(t[2]))) / 6.0;
  return volume;
}

// Closed and consistently oriented: every directed edge appears exactly once
// and its reverse exactly once.
bool isClosedAndOriented(const drb::TriangleMesh& mesh)
{
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e)
      ++directed[{ t[e], t[(e + 1) % 3] }];
  for (const auto& [edge, count] : directed)
  {
    const auto reverse = directed.find({ edge.second, edge.first });
    if (count != 1 || reverse == directed.end() || reverse->second != 1)
      return false;
  }
  return true;
}
}  // namespace

TEST(MeshLoader, StlTriangleSoupJoinsIntoEightCorners)
{
  const drb::TriangleMesh mesh = drb::loadMeshFile(kTestMeshDir + "/box_2x1x0.5.stl");
  EXPECT_EQ(mesh.vertices.cols(), 8);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_TRUE(isClosedAndOriented(mesh));
  EXPECT_NEAR(signedVolume(mesh), 2.0 * 1.0 * 0.5, kLengthTolerance);
}

TEST(MeshLoader, ObjWithScaleAndMirroring)
{
  const drb::TriangleMesh unit = drb::loadMeshFile(kTestMeshDir + "/tetrahedron.obj");
  ASSERT_EQ(unit.vertices.cols(), 4);
  EXPECT_NEAR(signedVolume(unit), 1.0 / 6.0, kLengthTolerance);
  // One mirrored axis keeps the mesh outward-oriented by flipping the winding.
  const drb::TriangleMesh mirrored = drb::loadMeshFile(kTestMeshDir + "/tetrahedron.obj", { -2.0, 3.0, 4.0 });
  // Vertices come in order of first use by the faces: the file's first face is 1 3 2.
  EXPECT_TRUE(mirrored.vertices.col(1).isApprox(Eigen::Vector3d(0, 3, 0), kLengthTolerance));
  EXPECT_TRUE(mirrored.vertices.col(2).isApprox(Eigen::Vector3d(-2, 0, 0), kLengthTolerance));
  EXPECT_NEAR(signedVolume(mirrored), 24.0 / 6.0, kLengthTolerance);
}

TEST(MeshLoader, AsciiPly)
{
  const std::string path = ::testing::TempDir() + "drb_square_pyramid.ply";
  {
    std::ofstream ply(path);
    ply << "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
           "element face 6\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n"
           "3 0 2 1\n3 0 3 2\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";
  }
  const drb::TriangleMesh mesh = drb::loadMeshFile(path);
  std::remove(path.c_str());
  EXPECT_EQ(mesh.vertices.cols(), 5);
  EXPECT_TRUE(isClosedAndOriented(mesh));
  EXPECT_NEAR(signedVolume(mesh), 1.0 / 3.0, 1e-7);  // float coordinates in the file
}

TEST(MeshLoader, ClearErrors)
{
  DRB_EXPECT_THROWS_MESSAGE(drb::loadMeshFile("/nonexistent/part.stl"), drb::MeshLoadError, "/nonexistent/part.stl");
  for (const Eigen::Vector3d& scale : { Eigen::Vector3d(0, 1, 1), Eigen::Vector3d(1, NAN, 1) })
    DRB_EXPECT_THROWS_MESSAGE(drb::loadMeshFile(kTestMeshDir + "/tetrahedron.obj", scale), drb::MeshLoadError,
                              "scale must be finite and non-zero");
  const std::string empty = ::testing::TempDir() + "drb_empty.obj";
  std::ofstream(empty) << "# no geometry\n";
  EXPECT_THROW(drb::loadMeshFile(empty), drb::MeshLoadError);
  std::remove(empty.c_str());
}

TEST(MeshLoader, JoinIdenticalVerticesKeepsFirstOccurrenceOrder)
{
  drb::TriangleMesh soup;
  soup.vertices.resize(3, 6);
  soup.vertices << 0, 1, 0, 1, 0, 0,  //
      0, 0, 1, 0, 1, 0,               //
      0, 0, 0, 0, -0.0, 1;            // -0.0 equals +0.0
  soup.triangles = { { 0, 1, 2 }, { 3, 4, 5 }, { 0, 3, 1 } };  // the last one degenerates
  const drb::TriangleMesh joined = drb::joinIdenticalVertices(soup);
  ASSERT_EQ(joined.vertices.cols(), 4);
  EXPECT_TRUE(joined.vertices.col(3).isApprox(Eigen::Vector3d(0, 0, 1)));
  ASSERT_EQ(joined.triangles.size(), 2u);
  EXPECT_EQ(joined.triangles[1], (std::array<std::uint32_t, 3>{ 1, 2, 3 }));
}

TEST(PrimitiveMesh, DocumentedResolutionClosedAndOutward)
{
  const double pi = std::acos(-1.0);
  const drb::TriangleMesh box = drb::boxMesh({ 1, 2, 3 });
  EXPECT_EQ(box.vertices.cols(), 8);
  EXPECT_TRUE(isClosedAndOriented(box));
  EXPECT_NEAR(signedVolume(box), 6.0, kLengthTolerance);
  EXPECT_TRUE(box.vertices.col(0).isApprox(Eigen::Vector3d(-0.5, -1, -1.5)));
  EXPECT_TRUE(box.vertices.col(1).isApprox(Eigen::Vector3d(0.5, -1, -1.5)));

  const drb::TriangleMesh sphere = drb::sphereMesh(2.0);
  EXPECT_EQ(sphere.vertices.cols(), 114);
  EXPECT_TRUE(isClosedAndOriented(sphere));
  EXPECT_NEAR(sphere.vertices.colwise().norm().maxCoeff(), 2.0, kLengthTolerance);
  EXPECT_NEAR(sphere.vertices.colwise().norm().minCoeff(), 2.0, kLengthTolerance);
  // Inscribed polyhedron: a little less than 4/3 pi r^3, within 10% at 16 x 8.
  EXPECT_LT(signedVolume(sphere), 4.0 / 3.0 * pi * 8.0);
  EXPECT_GT(signedVolume(sphere), 0.9 * 4.0 / 3.0 * pi * 8.0);

  const drb::TriangleMesh cylinder = drb::cylinderMesh(0.5, 2.0);
  EXPECT_EQ(cylinder.vertices.cols(), 64);
  EXPECT_TRUE(isClosedAndOriented(cylinder));
  // Inscribed 32-gon prism: (n/2) r^2 sin(2 pi / n) * length.
  EXPECT_NEAR(signedVolume(cylinder), 16.0 * 0.25 * std::sin(2.0 * pi / 32.0) * 2.0, kLengthTolerance);
}

// assimp stores positions as float32 (ai_real), so a text file's decimal
// coordinates are rounded once: |p_loaded - p_file| <= 2^-24 |p_file| per
// coordinate for correctly rounded parsing, 2^-23 allowing assimp's fast_atof
// one ulp. The oracle is the file's text read with strtod in double.
TEST(MeshLoader, TextCoordinatesCarryOneFloat32Rounding)
{
  const std::string path = kTestMeshDir + "/stanford/bunny.obj";
  std::ifstream file(path);
  ASSERT_TRUE(file) << path;
  std::vector<Eigen::Vector3d> exact;
  for (std::string line; std::getline(file, line);)
  {
    double x, y, z;
    if (std::sscanf(line.c_str(), "v %lf %lf %lf", &x, &y, &z) == 3)
      exact.emplace_back(x, y, z);
  }
  const drb::TriangleMesh mesh = drb::loadMeshFile(path);
  ASSERT_EQ(static_cast<std::size_t>(mesh.vertices.cols()), exact.size());
  // Pair each loaded vertex with its file vertex through the float32 rounding
  // of the file's value (a one-ulp parse difference falls back to a scan).
  std::map<std::array<float, 3>, Eigen::Vector3d> by_rounded;
  for (const Eigen::Vector3d& p : exact)
    by_rounded[{ static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()) }] = p;
  double worst_absolute = 0.0, worst_relative = 0.0;
  for (Eigen::Index v = 0; v < mesh.vertices.cols(); ++v)
  {
    const Eigen::Vector3d loaded = mesh.vertices.col(v);
    const auto found = by_rounded.find(
        { static_cast<float>(loaded.x()), static_cast<float>(loaded.y()), static_cast<float>(loaded.z()) });
    Eigen::Vector3d file_value = found != by_rounded.end() ? found->second : exact.front();
    if (found == by_rounded.end())
      for (const Eigen::Vector3d& p : exact)
        if ((p - loaded).norm() < (file_value - loaded).norm())
          file_value = p;
    for (int k = 0; k < 3; ++k)
    {
      const double error = std::abs(loaded[k] - file_value[k]);
      worst_absolute = std::max(worst_absolute, error);
      if (file_value[k] != 0.0)
        worst_relative = std::max(worst_relative, error / std::abs(file_value[k]));
      EXPECT_LE(error, std::ldexp(std::abs(file_value[k]), -23)) << "vertex " << v << " coordinate " << k;
    }
  }
  std::printf("[measured] bunny.obj (%zu vertices, text): float32 rounding of positions: max %.3g m, max %.3g "
              "relative (2^-24 = %.3g)\n",
              exact.size(), worst_absolute, worst_relative, std::ldexp(1.0, -24));
  EXPECT_GT(worst_absolute, 0.0) << "no rounding at all: positions are no longer float32 (update the README)";
}
