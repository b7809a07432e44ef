// Common inputs of the benchmarks: the state set with the hard cases of
// docs/derivation.md ("Hard cases"), bodies with extreme masses and
// inertias, vertex sets and meshes (the Stanford bunny and armadillo of
// test/meshes/stanford, generated spheres for 10^2 and 10^6 vertices).
// Fixed seeds: every run sees the same inputs.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/mass/triangle_mesh.h"
#include "diff_rigid_body/algorithm/free_body/vertex_columns.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"
#include "../test/support/meshes.h"  // readObj, shared with the tests

namespace drb_bench
{
namespace drb = diff_rigid_body;
using Vector6d = drb::Vector6<double>;
using Matrix3d = drb::Matrix3<double>;
using Matrix6d = drb::Matrix6<double>;
using Matrix3Xd = drb::Matrix3X<double>;

constexpr double kPi = 3.14159265358979323846;
constexpr double kHalfPi = kPi / 2;

/// A state with the class of hard case it belongs to.
struct TaggedState
{
  Vector6d q;
  std::string tag;  ///< "random", "gimbal", "large_angle"
};

/// A body: mass [kg], inertia about the COM in body axes [kg m^2].
struct TaggedBody
{
  double mass;
  Matrix3d inertia;
  std::string tag;  ///< "unit", "light", "heavy", "thin_rod"
};

inline Matrix3d randomRotation(std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> u(-kPi, kPi);
  return (Eigen::AngleAxisd(u(rng), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(u(rng), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(u(rng), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// Inertia with principal moments (y+z, x+z, x+y), x, y, z in [0.05, 1],
/// in random axes, times `scale`. Exactly symmetric.
inline Matrix3d randomInertia(std::mt19937_64& rng, double scale)
{
  std::uniform_real_distribution<double> u(0.05, 1.0);
  const double x = u(rng), y = u(rng), z = u(rng);
  const Matrix3d Q = randomRotation(rng);
  Matrix3d I = scale * Q * Eigen::Vector3d(y + z, x + z, x + y).asDiagonal() * Q.transpose();
  return (I + I.transpose()) / 2.0;
}

/// The state set for the error measurements: random states; gimbal lock
/// theta = +-pi/2 and +-pi/2 +- 10^-k, k = 1..16; angles up to 1e6 rad.
inline std::vector<TaggedState> errorStates()
{
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> angle(-kPi, kPi), position(-10.0, 10.0);
  std::vector<TaggedState> states;
  auto random_state = [&] {
    Vector6d q;
    for (int i = 0; i < 3; ++i)
      q[i] = angle(rng);
    for (int i = 3; i < 6; ++i)
      q[i] = position(rng);
    return q;
  };
  for (int i = 0; i < 32; ++i)
    states.push_back({ random_state(), "random" });
  std::vector<double> thetas = { kHalfPi, -kHalfPi };
  for (int k = 1; k <= 16; ++k)
    for (double base : { kHalfPi, -kHalfPi })
      for (double sign : { 1.0, -1.0 })
        thetas.push_back(base + sign * std::pow(10.0, -k));
  for (double theta : thetas)
  {
    Vector6d q = random_state();
    q[1] = theta;
    states.push_back({ q, "gimbal" });
  }
  const std::vector<double> large = { 1e6, -1e6, 999999.123456789, -987654.321, 123456.789, 31415.9265358979,
                                      1e5 + kHalfPi, 1e3 * kPi, 2.0 * kPi * 159154.0 + 0.25 };
  for (std::size_t i = 0; i < large.size(); ++i)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      Vector6d q = random_state();
      q[axis] = large[i];
      states.push_back({ q, "large_angle" });
    }
    Vector6d q = random_state();
    q.head<3>().setConstant(large[i]);
    states.push_back({ q, "large_angle" });
  }
  return states;
}

/// Bodies for the error measurements: unit scale, masses 1e-9 and 1e9 kg
/// (inertia scaled with them), and a thin rod I = diag(1e-9, 1, 1) on the
/// edge of the triangle inequality, in random axes.
inline std::vector<TaggedBody> errorBodies()
{
  std::mt19937_64 rng(7);
  std::vector<TaggedBody> bodies;
  bodies.push_back({ 1.0, randomInertia(rng, 1.0), "unit" });
  bodies.push_back({ 2.5, randomInertia(rng, 0.3), "unit" });
  bodies.push_back({ 1e-9, randomInertia(rng, 1e-12), "light" });
  bodies.push_back({ 1e9, randomInertia(rng, 1e10), "heavy" });
  const Matrix3d Q = randomRotation(rng);
  Matrix3d rod = Q * Eigen::Vector3d(1e-9, 1.0, 1.0).asDiagonal() * Q.transpose();
  bodies.push_back({ 12.0, (rod + rod.transpose()) / 2.0, "thin_rod" });
  bodies.push_back({ 3.0, Eigen::Vector3d(1e-9, 1.0, 1.0).asDiagonal(), "thin_rod" });
  return bodies;
}

/// Vertices for the error measurements: random directions at norms 1e-6,
/// 1e-3, 1, 1e2 and 1e4 m (bodies as small as 1e-6 m, vertices up to 1e4 m
/// from the COM). Column tags give the scale class.
inline Matrix3Xd errorVertices(std::vector<double>* norms = nullptr)
{
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  const std::vector<double> scales = { 1e-6, 1e-3, 1.0, 1e2, 1e4 };
  const int per_scale = 8;
  Matrix3Xd v(3, static_cast<Eigen::Index>(scales.size() * per_scale));
  Eigen::Index c = 0;
  for (double s : scales)
    for (int k = 0; k < per_scale; ++k, ++c)
    {
      v.col(c) = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized() * s;
      if (norms)
        norms->push_back(s);
    }
  return v;
}

/// States for the timing loops: angles vary from call to call (no hoisted
/// trigonometry), a few in the hard classes. Sized to stay in L1.
inline std::vector<Vector6d> timingStates(std::size_t count = 256)
{
  std::vector<TaggedState> hard = errorStates();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-kPi, kPi), position(-10.0, 10.0);
  std::vector<Vector6d> states;
  for (std::size_t i = 0; i < count; ++i)
  {
    Vector6d q;
    if (i % 8 == 7)
      q = hard[(i * 13) % hard.size()].q;
    else
    {
      for (int k = 0; k < 3; ++k)
        q[k] = angle(rng);
      for (int k = 3; k < 6; ++k)
        q[k] = position(rng);
    }
    states.push_back(q);
  }
  return states;
}

// ---------------------------------------------------------------------------
// Meshes.

/// A closed, star-shaped "bumpy sphere" of about `target` vertices (a UV
/// sphere with two poles, radius 0.1 m modulated by low-order harmonics, so
/// it has curvature everywhere like a scanned model).
inline drb::TriangleMesh bumpySphere(std::size_t target)
{
  const int rings = std::max(3, static_cast<int>(std::lround(std::sqrt(target / 2.0))));
  const int segments = std::max(3, static_cast<int>((static_cast<long>(target) - 2 + rings - 2) / (rings - 1)));
  drb::TriangleMesh mesh;
  const Eigen::Index count = 2 + static_cast<Eigen::Index>(rings - 1) * segments;
  mesh.vertices.resize(3, count);
  auto radius = [](double theta, double phi) {
    return 0.1 * (1.0 + 0.15 * std::sin(3 * theta) * std::cos(4 * phi) + 0.08 * std::cos(5 * phi + 2 * theta));
  };
  mesh.vertices.col(0) = Eigen::Vector3d(0, 0, radius(0, 0));
  Eigen::Index c = 1;
  for (int r = 1; r < rings; ++r)
  {
    const double theta = kPi * r / rings;
    for (int s = 0; s < segments; ++s, ++c)
    {
      const double phi = 2 * kPi * s / segments;
      const double rho = radius(theta, phi);
      mesh.vertices.col(c) =
          Eigen::Vector3d(rho * std::sin(theta) * std::cos(phi), rho * std::sin(theta) * std::sin(phi),
                          rho * std::cos(theta));
    }
  }
  mesh.vertices.col(c) = Eigen::Vector3d(0, 0, -radius(kPi, 0));
  const std::uint32_t south = static_cast<std::uint32_t>(c);
  auto at = [&](int r, int s) { return static_cast<std::uint32_t>(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s)
    mesh.triangles.push_back({ 0, at(1, s), at(1, s + 1) });
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s)
    {
      mesh.triangles.push_back({ at(r, s), at(r + 1, s), at(r + 1, s + 1) });
      mesh.triangles.push_back({ at(r, s), at(r + 1, s + 1), at(r, s + 1) });
    }
  for (int s = 0; s < segments; ++s)
    mesh.triangles.push_back({ south, at(rings - 1, s + 1), at(rings - 1, s) });
  return mesh;
}

/// A named mesh read from this repository's test/meshes/stanford (the
/// Stanford bunny or armadillo; see the README.md there).
struct NamedMesh
{
  std::string name;
  drb::TriangleMesh mesh;
};

/// `name`.obj from DRB_MESH_DIR (set by CMakeLists.txt to
/// <repo>/test/meshes/stanford). The meshes are part of the repository, so a
/// missing one is an error: exits with status 2 and a message.
inline NamedMesh stanfordMesh(const std::string& name)
{
#ifdef DRB_MESH_DIR
  const std::string path = std::string(DRB_MESH_DIR) + "/" + name + ".obj";
#else
  const std::string path = "(DRB_MESH_DIR not defined by the build)/" + name + ".obj";
#endif
  NamedMesh out;
  out.name = name;
  if (!drb_test::readObj(path, &out.mesh))
  {
    std::fprintf(stderr, "benchmark mesh %s is missing or unreadable\n", path.c_str());
    std::exit(2);
  }
  return out;
}

/// Vertex sets of the Jacobian benchmarks: 10^2 (generated), bunny (~1.4e4),
/// armadillo (~2.5e4) and 10^6 (generated).
struct VertexSet
{
  std::string name;
  Matrix3Xd vertices;
};

inline std::vector<VertexSet> jacobianVertexSets()
{
  std::vector<VertexSet> sets;
  sets.push_back({ "generated-1e2", bumpySphere(100).vertices });
  NamedMesh bunny = stanfordMesh("bunny");
  sets.push_back({ bunny.name, bunny.mesh.vertices });
  NamedMesh armadillo = stanfordMesh("armadillo");
  sets.push_back({ armadillo.name, armadillo.mesh.vertices });
  sets.push_back({ "generated-1e6", bumpySphere(1000000).vertices });
  return sets;
}

}  // namespace drb_bench
