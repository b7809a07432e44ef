// Mass properties: each algorithm is checked against an independent oracle.
//   composite (parallel-axis)   <- direct particle sum, eq. (17), over all particles
//   mesh integral               <- closed forms (box, n-gon prism, sphere limit) and
//                                  a 4-point tetrahedron quadrature of the same polyhedron
//   primitives                  <- textbook numbers and fine-grid midpoint sums
//   particle sum on a mesh      <- brute-force eq. (17) over the same grid with a
//                                  half-space inside test; converges to the mesh integral
//   bunny                       <- exact integral vs 1e6 particles
// eq. (17) is the seed's particle sum; the formulas are in docs/derivation.md ("Inertia").
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <functional>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mass_properties.h"
#include "reference/particle_mass_properties.h"
#include "../support/expect_throws.h"
#include "../support/meshes.h"

using diff_rigid_body::boxMassProperties;
using diff_rigid_body::combineMassProperties;
using diff_rigid_body::cylinderMassProperties;
using diff_rigid_body::InvalidArgumentError;
using diff_rigid_body::InvalidInertiaError;
using diff_rigid_body::MassProperties;
using diff_rigid_body::MeshLoadError;
using diff_rigid_body::meshMassProperties;
using diff_rigid_body::meshWindingNumber;
using diff_rigid_body::ParticleMassProperties;
using diff_rigid_body::particleMassProperties;
using diff_rigid_body::sphereMassProperties;
using diff_rigid_body::transformMassProperties;
using diff_rigid_body::TriangleMesh;
using drb_test::makeMesh;
using drb_test::readObj;

namespace
{
constexpr double kPi = 3.14159265358979323846;

// Round-off tolerances, relative unless a unit is given.
constexpr double ROUNDOFF_REL_TOL = 1e-12;        // a few hundred ulp
constexpr double COM_ABS_TOL = 1e-13;             // m, for bodies of size ~1 m near the origin

// ---------------------------------------------------------------------------
// Helpers independent of the code under test.

double relativeError(const Eigen::Matrix3d& value, const Eigen::Matrix3d& reference)
{
  return (value - reference).norm() / reference.norm();
}

double relativeError(double value, double reference)
{
  return std::abs(value - reference) / std::abs(reference);
}

/// Eq. (17): m = sum m_i, com = sum m_i p_i / m, I = sum m_i (|r_i|^2 I3 - r_i r_i^T), r_i = p_i - com.
MassProperties particleSum(const std::vector<double>& masses, const std::vector<Eigen::Vector3d>& points)
{
  // Moments about the first point, so far-off positions cost no accuracy.
  MassProperties out;
  const Eigen::Vector3d reference = points.front();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < masses.size(); ++i)
  {
    out.mass += masses[i];
    moment += masses[i] * (points[i] - reference);
  }
  out.com = reference + moment / out.mass;
  for (std::size_t i = 0; i < masses.size(); ++i)
  {
    const Eigen::Vector3d r = points[i] - out.com;
    out.inertia += masses[i] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  return out;
}

Eigen::Isometry3d randomPose(std::mt19937& rng, double translation_scale)
{
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = translation_scale * Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
  return pose;
}

/// Axis-aligned box centred at the origin, 8 vertices, 12 outward triangles.
TriangleMesh boxMesh(const Eigen::Vector3d& size)
{
  std::vector<Eigen::Vector3d> v;
  for (int i = 0; i < 8; ++i)  // bit 0: x, bit 1: y, bit 2: z
    v.push_back(0.5 * size.cwiseProduct(Eigen::Vector3d((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1)));
  return makeMesh(v, { { 0, 2, 1 }, { 1, 2, 3 },    // z = -c/2
                       { 4, 5, 6 }, { 5, 7, 6 },    // z = +c/2
                       { 0, 1, 4 }, { 1, 5, 4 },    // y = -b/2
                       { 2, 6, 3 }, { 3, 6, 7 },    // y = +b/2
                       { 0, 4, 2 }, { 2, 4, 6 },    // x = -a/2
                       { 1, 3, 5 }, { 3, 7, 5 } }); // x = +a/2
}

TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Isometry3d& pose)
{
  TriangleMesh out = mesh;
  for (Eigen::Index i = 0; i < out.vertices.cols(); ++i)
    out.vertices.col(i) = pose * Eigen::Vector3d(mesh.vertices.col(i));
  return out;
}

TriangleMesh reversed(const TriangleMesh& mesh)
{
  TriangleMesh out = mesh;
  for (auto& t : out.triangles)
    std::swap(t[1], t[2]);
  return out;
}

/// Icosahedron subdivided `levels` times (each edge halved, new vertices
/// pushed to the sphere). Inscribed in the sphere of `radius`; symmetric
/// under x -> -x (and y, z), outward-oriented.
TriangleMesh icosphere(int levels, double radius)
{
  const double phi = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<Eigen::Vector3d> v = { { -1, phi, 0 }, { 1, phi, 0 }, { -1, -phi, 0 }, { 1, -phi, 0 },
                                     { 0, -1, phi }, { 0, 1, phi }, { 0, -1, -phi }, { 0, 1, -phi },
                                     { phi, 0, -1 }, { phi, 0, 1 }, { -phi, 0, -1 }, { -phi, 0, 1 } };
  for (auto& p : v)
    p.normalize();
  std::vector<std::array<std::uint32_t, 3>> f = { { 0, 11, 5 }, { 0, 5, 1 },  { 0, 1, 7 },   { 0, 7, 10 }, { 0, 10, 11 },
                                                  { 1, 5, 9 },  { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 },
                                                  { 3, 9, 4 },  { 3, 4, 2 },  { 3, 2, 6 },   { 3, 6, 8 },  { 3, 8, 9 },
                                                  { 4, 9, 5 },  { 2, 4, 11 }, { 6, 2, 10 },  { 8, 6, 7 },  { 9, 8, 1 } };
  for (int level = 0; level < levels; ++level)
  {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      const auto it = midpoints.find(key);
      if (it != midpoints.end())
        return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const auto index = static_cast<std::uint32_t>(v.size() - 1);
      midpoints[key] = index;
      return index;
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    for (const auto& t : f)
    {
      const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      finer.push_back({ t[0], ab, ca });
      finer.push_back({ t[1], bc, ab });
      finer.push_back({ t[2], ca, bc });
      finer.push_back({ ab, bc, ca });
    }
    f = finer;
  }
  for (auto& p : v)
    p *= radius;
  return makeMesh(v, f);
}

/// Regular n-gon prism of circumradius r, axis z, from z = -l/2 to l/2, capped by fans from the axis.
TriangleMesh prismMesh(int n, double r, double l)
{
  std::vector<Eigen::Vector3d> v;
  for (int side = 0; side < 2; ++side)
    for (int i = 0; i < n; ++i)
      v.emplace_back(r * std::cos(2 * kPi * i / n), r * std::sin(2 * kPi * i / n), side ? 0.5 * l : -0.5 * l);
  v.emplace_back(0, 0, -0.5 * l);
  v.emplace_back(0, 0, 0.5 * l);
  const auto N = static_cast<std::uint32_t>(n);
  std::vector<std::array<std::uint32_t, 3>> f;
  for (std::uint32_t i = 0; i < N; ++i)
  {
    const std::uint32_t j = (i + 1) % N;
    f.push_back({ 2 * N, j, i });          // bottom cap
    f.push_back({ 2 * N + 1, N + i, N + j });  // top cap
    f.push_back({ i, j, N + j });          // side
    f.push_back({ i, N + j, N + i });
  }
  return makeMesh(v, f);
}

/// Volume of a polyhedron star-shaped about the origin, as pyramids: sum area_f * height_f / 3.
double pyramidVolume(const TriangleMesh& mesh)
{
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
  {
    const Eigen::Vector3d a = mesh.vertices.col(t[0]), b = mesh.vertices.col(t[1]), c = mesh.vertices.col(t[2]);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    volume += 0.5 * n.norm() * n.normalized().dot(a) / 3.0;
  }
  return volume;
}

/// integral x x^T dV over the tetrahedra (0, a, b, c), signed, by the 4-point
/// degree-2 rule (exact for quadratics): points alpha v_i + beta sum_{j != i} v_j, weights V/4.
Eigen::Matrix3d quadratureSecondMoment(const TriangleMesh& mesh)
{
  const double alpha = 0.5854101966249685, beta = 0.1381966011250105;
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& t : mesh.triangles)
  {
    const Eigen::Vector3d v[4] = { Eigen::Vector3d::Zero(), mesh.vertices.col(t[0]), mesh.vertices.col(t[1]),
                                   mesh.vertices.col(t[2]) };
    const double volume = (v[2] - v[1]).cross(v[3] - v[1]).dot(v[0] - v[1]) / -6.0;
    const Eigen::Vector3d sum = v[0] + v[1] + v[2] + v[3];
    for (const auto& vi : v)
    {
      const Eigen::Vector3d x = alpha * vi + beta * (sum - vi);
      second += 0.25 * volume * x * x.transpose();
    }
  }
  return second;
}

/// Inertia about the COM from the second moment about the origin S (density 1): tr(S_c) I3 - S_c.
Eigen::Matrix3d inertiaAboutCom(const Eigen::Matrix3d& second_about_origin, double volume, const Eigen::Vector3d& com)
{
  const Eigen::Matrix3d S = second_about_origin - volume * com * com.transpose();
  return S.trace() * Eigen::Matrix3d::Identity() - S;
}

}  // namespace

// ===========================================================================
// Composite (parallel-axis theorem)

TEST(MassPropertiesComposite, MatchesDirectParticleSum)
{
  // Random point masses in the target frame, in 4 groups of mixed mass scale.
  // Each group is a part given in its own random frame; the composite must
  // equal eq. (17) over all particles.
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double group_mass_scale[] = { 1e-3, 1.0, 10.0, 1e3 };  // kg
  std::vector<double> all_masses;
  std::vector<Eigen::Vector3d> all_points;
  std::vector<std::pair<Eigen::Isometry3d, MassProperties>> parts;
  for (double scale : group_mass_scale)
  {
    const Eigen::Isometry3d pose = randomPose(rng, 2.0);
    const Eigen::Vector3d group_centre = 3.0 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    std::vector<double> masses;
    std::vector<Eigen::Vector3d> local;
    for (int i = 0; i < 40; ++i)
    {
      const double m = scale * (0.1 + unit(rng));
      const Eigen::Vector3d p = group_centre + Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) - Eigen::Vector3d::Constant(0.5);
      masses.push_back(m);
      local.push_back(pose.inverse() * p);
      all_masses.push_back(m);
      all_points.push_back(p);
    }
    parts.emplace_back(pose, particleSum(masses, local));
  }
  const MassProperties reference = particleSum(all_masses, all_points);
  const MassProperties composite = combineMassProperties(parts);
  EXPECT_LT(relativeError(composite.mass, reference.mass), ROUNDOFF_REL_TOL);
  EXPECT_LT((composite.com - reference.com).norm(), COM_ABS_TOL);
  EXPECT_LT(relativeError(composite.inertia, reference.inertia), ROUNDOFF_REL_TOL)
      << "composite\n" << composite.inertia << "\nreference\n" << reference.inertia;
}

TEST(MassPropertiesComposite, TwoHalfBoxesMakeTheBox)
{
  // Two boxes a/2 x b x c at x = -+a/4, one of them given rotated by pi about z
  // (a symmetry of the box), combine to the a x b x c box.
  const double density = 750.0;  // kg/m^3
  const Eigen::Vector3d size(0.4, 0.7, 1.3);
  const MassProperties half = boxMassProperties(density, Eigen::Vector3d(size.x() / 2, size.y(), size.z()));
  Eigen::Isometry3d left = Eigen::Isometry3d::Identity();
  left.translation() = Eigen::Vector3d(-size.x() / 4, 0, 0);
  Eigen::Isometry3d right = Eigen::Isometry3d::Identity();
  right.linear() = Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  right.translation() = Eigen::Vector3d(size.x() / 4, 0, 0);
  const MassProperties whole = combineMassProperties({ { left, half }, { right, half } });
  const MassProperties expected = boxMassProperties(density, size);
  EXPECT_LT(relativeError(whole.mass, expected.mass), ROUNDOFF_REL_TOL);
  EXPECT_LT(whole.com.norm(), COM_ABS_TOL);
  EXPECT_LT(relativeError(whole.inertia, expected.inertia), ROUNDOFF_REL_TOL) << whole.inertia;
}

TEST(MassPropertiesComposite, SinglePartIsRigidTransform)
{
  std::mt19937 rng(7);
  const Eigen::Isometry3d pose = randomPose(rng, 5.0);
  MassProperties part = boxMassProperties(1000.0, Eigen::Vector3d(0.1, 0.2, 0.3));
  part.com = Eigen::Vector3d(0.01, -0.02, 0.03);
  const MassProperties moved = combineMassProperties({ { pose, part } });
  const Eigen::Matrix3d R = pose.linear();
  EXPECT_DOUBLE_EQ(moved.mass, part.mass);
  EXPECT_LT((moved.com - (R * part.com + pose.translation())).norm(), COM_ABS_TOL);
  EXPECT_LT(relativeError(moved.inertia, R * part.inertia * R.transpose()), ROUNDOFF_REL_TOL);
  const MassProperties transformed_part = transformMassProperties(pose, part);
  EXPECT_LT(relativeError(transformed_part.inertia, moved.inertia), ROUNDOFF_REL_TOL);
}

TEST(MassPropertiesComposite, RejectsBadParts)
{
  const MassProperties good = boxMassProperties(1.0, Eigen::Vector3d::Ones());
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  EXPECT_THROW(combineMassProperties({}, "link 'base'"), InvalidInertiaError);
  DRB_EXPECT_THROWS_MESSAGE((combineMassProperties({}, "link 'base'")), std::exception, "link 'base'");
  MassProperties negative = good;
  negative.mass = -1.0;
  EXPECT_THROW(combineMassProperties({ { I, good }, { I, negative } }), InvalidInertiaError);
  DRB_EXPECT_THROWS_MESSAGE((combineMassProperties({ { I, good }, { I, negative } }, "link 'arm'")), std::exception,
                            "part 1");
  MassProperties nan_com = good;
  nan_com.com.x() = std::numeric_limits<double>::quiet_NaN();
  DRB_EXPECT_THROWS_MESSAGE((combineMassProperties({ { I, nan_com } })), std::exception, "COM must be finite");
  MassProperties massless = good;
  massless.mass = 0.0;
  DRB_EXPECT_THROWS_MESSAGE((combineMassProperties({ { I, massless } })), std::exception, "total mass");
  Eigen::Isometry3d scaled = I;
  scaled.linear() *= 2.0;
  DRB_EXPECT_THROWS_MESSAGE((combineMassProperties({ { scaled, good } })), std::exception, "orthonormal");
}

// ===========================================================================
// Closed-form primitives

TEST(MassPropertiesPrimitives, TextbookValues)
{
  // Numbers worked out by hand from m = rho V and the table of moments.
  const MassProperties box = boxMassProperties(1000.0, Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(box.mass, 6000.0, 6000.0 * ROUNDOFF_REL_TOL);
  EXPECT_LT(relativeError(box.inertia, Eigen::Vector3d(6500, 5000, 2500).asDiagonal().toDenseMatrix()), ROUNDOFF_REL_TOL);
  const MassProperties sphere = sphereMassProperties(1000.0, 0.5);
  EXPECT_NEAR(sphere.mass, 523.5987755982989, 523.6 * ROUNDOFF_REL_TOL);
  EXPECT_LT(relativeError(sphere.inertia, 52.35987755982988 * Eigen::Matrix3d::Identity()), ROUNDOFF_REL_TOL);
  const MassProperties cylinder = cylinderMassProperties(7800.0, 0.1, 2.0);
  EXPECT_NEAR(cylinder.mass, 490.08845396000777, 490.1 * ROUNDOFF_REL_TOL);
  EXPECT_LT(relativeError(cylinder.inertia,
                          Eigen::Vector3d(164.5880391215693, 164.5880391215693, 2.450442269800039).asDiagonal().toDenseMatrix()),
            ROUNDOFF_REL_TOL);
  for (const MassProperties& p : { box, sphere, cylinder })
    EXPECT_EQ(p.com, Eigen::Vector3d::Zero());
}

TEST(MassPropertiesPrimitives, MatchFineGridSums)
{
  // Midpoint-rule particle sums over an n^3 grid of the bounding box, keeping
  // the cells whose centre is inside the shape.
  //  - box: the mass is exact and each second moment is short by the factor
  //    (1 - 1/n^2), i.e. 2.5e-5 at n = 200;
  //  - sphere, cylinder: the lattice-point count in a disc or ball of radius
  //    R = n/2 cells errs by O(R^(2/3)) cells per section (Gauss circle
  //    problem), ~7e-4 relative at R = 100; measured 2.5e-5 / 4.2e-5 (sphere)
  //    and 3.8e-4 / 4.6e-4 (cylinder) in mass / inertia.
  constexpr int n = 200;                        // cells per axis
  constexpr double BOX_GRID_REL_TOL = 5e-5;     // relative, 2x the exact 1/n^2
  constexpr double CURVED_GRID_REL_TOL = 1e-3;  // relative
  const double density = 1200.0;                // kg/m^3
  struct Case
  {
    const char* name;
    MassProperties closed_form;
    Eigen::Vector3d half_extent;  // m
    std::function<bool(const Eigen::Vector3d&)> inside;
    double tolerance;
  };
  const double r = 0.3, l = 1.1;
  const Eigen::Vector3d box_size(0.5, 0.8, 1.1);
  const Case cases[] = {
    { "box", boxMassProperties(density, box_size), 0.5 * box_size, [](const Eigen::Vector3d&) { return true; },
      BOX_GRID_REL_TOL },
    { "sphere", sphereMassProperties(density, r), Eigen::Vector3d::Constant(r),
      [r](const Eigen::Vector3d& p) { return p.squaredNorm() < r * r; }, CURVED_GRID_REL_TOL },
    { "cylinder", cylinderMassProperties(density, r, l), Eigen::Vector3d(r, r, 0.5 * l),
      [r](const Eigen::Vector3d& p) { return p.head<2>().squaredNorm() < r * r; }, CURVED_GRID_REL_TOL },
  };
  for (const Case& c : cases)
  {
    const Eigen::Vector3d h = 2.0 * c.half_extent / n;
    const double cell_mass = density * h.prod();
    double mass = 0.0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
        {
          const Eigen::Vector3d p = -c.half_extent + h.cwiseProduct(Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
          if (!c.inside(p))
            continue;
          mass += cell_mass;
          moment += cell_mass * p;
          second += cell_mass * p * p.transpose();
        }
    const Eigen::Vector3d com = moment / mass;
    const Eigen::Matrix3d S = second - mass * com * com.transpose();
    const Eigen::Matrix3d inertia = S.trace() * Eigen::Matrix3d::Identity() - S;
    EXPECT_LT(relativeError(mass, c.closed_form.mass), c.tolerance) << c.name;
    EXPECT_LT(com.norm(), COM_ABS_TOL) << c.name;
    EXPECT_LT(relativeError(inertia, c.closed_form.inertia), c.tolerance) << c.name << "\n" << inertia;
  }
}

TEST(MassPropertiesPrimitives, RejectNonPositiveOrNonFiniteArguments)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(boxMassProperties(0.0, Eigen::Vector3d::Ones()), InvalidArgumentError);
  EXPECT_THROW(boxMassProperties(1.0, Eigen::Vector3d(1, -1, 1)), InvalidArgumentError);
  EXPECT_THROW(sphereMassProperties(nan, 1.0), InvalidArgumentError);
  EXPECT_THROW(sphereMassProperties(1.0, 0.0), InvalidArgumentError);
  EXPECT_THROW(cylinderMassProperties(-1.0, 1.0, 1.0), InvalidArgumentError);
  EXPECT_THROW(cylinderMassProperties(1.0, 1.0, std::numeric_limits<double>::infinity()), InvalidArgumentError);
  DRB_EXPECT_THROWS_MESSAGE((boxMassProperties(1.0, Eigen::Vector3d(1, -1, 1))), std::exception, "size y");
  DRB_EXPECT_THROWS_MESSAGE((sphereMassProperties(nan, 1.0)), std::exception, "density");
}

// ===========================================================================
// Exact mesh integral

TEST(MassPropertiesMesh, BoxMeshMatchesClosedForm)
{
  const double density = 800.0;  // kg/m^3
  const Eigen::Vector3d size(0.3, 0.5, 0.7);
  const MassProperties mesh = meshMassProperties(density, boxMesh(size));
  const MassProperties closed = boxMassProperties(density, size);
  EXPECT_LT(relativeError(mesh.mass, closed.mass), ROUNDOFF_REL_TOL);
  EXPECT_LT(mesh.com.norm(), COM_ABS_TOL);
  EXPECT_LT(relativeError(mesh.inertia, closed.inertia), ROUNDOFF_REL_TOL) << mesh.inertia;
}

TEST(MassPropertiesMesh, FarAwayRotatedBoxMeshIsStillExact)
{
  // Vertices 1e3 m and 1e4 m from the origin: rounding the vertices alone
  // moves them by up to |t| eps = 2e-12 m on a 0.3 m box, a relative change
  // in the inertia of ~1e-11 (measured 9e-14 at 1e3 m, 1.4e-12 at 1e4 m).
  // Without subtracting a reference point the signed tetrahedra from the
  // origin cancel ~|t|^2/size^2 = 1e7..1e9-fold and the inertia loses most
  // of its digits.
  constexpr double FAR_INERTIA_REL_TOL = 1e-10;  // relative
  constexpr double FAR_COM_REL_TOL = 1e-14;      // relative to |t|
  const double density = 2700.0;                // kg/m^3
  const Eigen::Vector3d size(0.3, 0.5, 0.7);
  const MassProperties closed = boxMassProperties(density, size);
  std::mt19937 rng(99);
  for (double distance : { 1e3, 1e4 })
  {
    Eigen::Isometry3d pose = randomPose(rng, 1.0);
    pose.translation() = distance * Eigen::Vector3d(0.6, -0.48, 0.64);  // |t| = distance
    const MassProperties mesh = meshMassProperties(density, transformed(boxMesh(size), pose));
    const Eigen::Matrix3d R = pose.linear();
    EXPECT_LT(relativeError(mesh.mass, closed.mass), FAR_INERTIA_REL_TOL) << distance;
    EXPECT_LT((mesh.com - pose.translation()).norm(), FAR_COM_REL_TOL * distance) << distance;
    EXPECT_LT(relativeError(mesh.inertia, R * closed.inertia * R.transpose()), FAR_INERTIA_REL_TOL)
        << "at " << distance << " m\n" << mesh.inertia;
  }
}

TEST(MassPropertiesMesh, InwardOrientedMeshIsFlipped)
{
  std::mt19937 rng(3);
  const TriangleMesh outward = transformed(icosphere(2, 0.4), randomPose(rng, 1.0));
  const MassProperties a = meshMassProperties(500.0, outward);
  const MassProperties b = meshMassProperties(500.0, reversed(outward));
  EXPECT_GT(b.mass, 0.0);
  EXPECT_LT(relativeError(b.mass, a.mass), ROUNDOFF_REL_TOL);
  EXPECT_LT((b.com - a.com).norm(), COM_ABS_TOL);
  EXPECT_LT(relativeError(b.inertia, a.inertia), ROUNDOFF_REL_TOL);
}

TEST(MassPropertiesMesh, IcosphereConvergesToSphereAsInscribedPolyhedron)
{
  // The level-L icosphere is a polyhedron inscribed in the sphere with edge
  // h ~ 2^-L. (1) Its own volume and inertia, computed independently (pyramid
  // volumes area*height/3 and a 4-point tetrahedron quadrature), match the
  // mesh integral to round-off. (2) Its deficit against the sphere is O(h^2):
  // each halving of h cuts the error by ~4 (measured 3.90-4.00 for L = 3..6),
  // and it is bounded by containment: the polyhedron holds the ball of radius
  // d_min (its nearest face plane), so V_poly >= 4/3 pi d_min^3 and, its
  // inertia being isotropic, I_poly >= I_ball(d_min); the relative deficits are
  // at most 1 - (d_min/R)^3 and 1 - (d_min/R)^5. At L = 6 they are 1.35e-4 and
  // 2.25e-4.
  constexpr double CONVERGENCE_RATIO_MIN = 3.8;
  constexpr double CONVERGENCE_RATIO_MAX = 4.2;
  constexpr double LEVEL6_MASS_REL_ERROR_MAX = 1.5e-4;     // relative
  constexpr double LEVEL6_INERTIA_REL_ERROR_MAX = 2.5e-4;  // relative
  const double radius = 0.25;   // m
  const double density = 1000;  // kg/m^3
  const MassProperties sphere = sphereMassProperties(density, radius);
  double previous_mass_error = 0.0, previous_inertia_error = 0.0;
  for (int level = 2; level <= 6; ++level)
  {
    const TriangleMesh mesh = icosphere(level, radius);
    const MassProperties exact = meshMassProperties(density, mesh);
    // (1) same polyhedron, independent formulas.
    const double volume = pyramidVolume(mesh);
    EXPECT_LT(relativeError(exact.mass, density * volume), ROUNDOFF_REL_TOL) << level;
    EXPECT_LT(exact.com.norm(), COM_ABS_TOL) << level;
    const Eigen::Matrix3d quadrature = density * inertiaAboutCom(quadratureSecondMoment(mesh), volume, Eigen::Vector3d::Zero());
    EXPECT_LT(relativeError(exact.inertia, quadrature), ROUNDOFF_REL_TOL) << level;
    // Icosahedral symmetry makes the inertia isotropic.
    const double mean_moment = exact.inertia.trace() / 3.0;
    EXPECT_LT((exact.inertia - mean_moment * Eigen::Matrix3d::Identity()).norm() / mean_moment, ROUNDOFF_REL_TOL);
    // (2) O(h^2) convergence to the sphere, from below.
    const double mass_error = relativeError(exact.mass, sphere.mass);
    const double inertia_error = relativeError(exact.inertia, sphere.inertia);
    double d_min = radius;
    for (const auto& t : mesh.triangles)
    {
      const Eigen::Vector3d a = mesh.vertices.col(t[0]), b = mesh.vertices.col(t[1]), c = mesh.vertices.col(t[2]);
      d_min = std::min(d_min, (b - a).cross(c - a).normalized().dot(a));
    }
    EXPECT_GT(mass_error, 0.0) << level;  // inscribed: from below
    EXPECT_LT(mass_error, 1.0 - std::pow(d_min / radius, 3)) << level;
    EXPECT_GT(inertia_error, 0.0) << level;
    EXPECT_LT(inertia_error, 1.0 - std::pow(d_min / radius, 5)) << level;
    EXPECT_LT(exact.mass, sphere.mass) << level;
    if (level > 2)
    {
      EXPECT_GT(previous_mass_error / mass_error, CONVERGENCE_RATIO_MIN) << level;
      EXPECT_LT(previous_mass_error / mass_error, CONVERGENCE_RATIO_MAX) << level;
      EXPECT_GT(previous_inertia_error / inertia_error, CONVERGENCE_RATIO_MIN) << level;
      EXPECT_LT(previous_inertia_error / inertia_error, CONVERGENCE_RATIO_MAX) << level;
    }
    previous_mass_error = mass_error;
    previous_inertia_error = inertia_error;
  }
  EXPECT_LT(previous_mass_error, LEVEL6_MASS_REL_ERROR_MAX);
  EXPECT_LT(previous_inertia_error, LEVEL6_INERTIA_REL_ERROR_MAX);
}

TEST(MassPropertiesMesh, PrismConvergesToCylinder)
{
  // A regular n-gon prism has, with A = n/2 r^2 sin(2pi/n) and polar moment
  // J = n r^4 sin(2pi/n) (2 + cos(2pi/n)) / 12 (sum of the n centre triangles),
  //   m = rho A l,  Izz = rho l J,  Ixx = Iyy = rho (l J/2 + A l^3/12).
  // The mesh integral must match that to round-off, and approach the
  // cylinder as (2pi/n)^2: doubling n cuts the error by ~4.
  constexpr double CONVERGENCE_RATIO_MIN = 3.9;
  constexpr double CONVERGENCE_RATIO_MAX = 4.1;
  const double r = 0.05, l = 0.6, density = 7850.0;  // m, m, kg/m^3
  const MassProperties cylinder = cylinderMassProperties(density, r, l);
  double previous_error = 0.0;
  for (int n : { 16, 32, 64, 128, 256 })
  {
    const double s = std::sin(2 * kPi / n), c = std::cos(2 * kPi / n);
    const double A = 0.5 * n * r * r * s;
    const double J = n * r * r * r * r * s * (2 + c) / 12.0;
    const Eigen::Matrix3d expected =
        Eigen::Vector3d(density * (l * J / 2 + A * l * l * l / 12), density * (l * J / 2 + A * l * l * l / 12),
                        density * l * J).asDiagonal();
    const MassProperties mesh = meshMassProperties(density, prismMesh(n, r, l));
    EXPECT_LT(relativeError(mesh.mass, density * A * l), ROUNDOFF_REL_TOL) << n;
    EXPECT_LT(mesh.com.norm(), COM_ABS_TOL) << n;
    EXPECT_LT(relativeError(mesh.inertia, expected), ROUNDOFF_REL_TOL) << n;
    const double error = relativeError(mesh.inertia, cylinder.inertia);
    if (n > 16)
    {
      EXPECT_GT(previous_error / error, CONVERGENCE_RATIO_MIN) << n;
      EXPECT_LT(previous_error / error, CONVERGENCE_RATIO_MAX) << n;
    }
    previous_error = error;
  }
}

TEST(MassPropertiesMesh, RejectsBadMeshesAndDensities)
{
  const TriangleMesh box = boxMesh(Eigen::Vector3d(1, 2, 3));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Density.
  for (double density : { 0.0, -1.0, nan, std::numeric_limits<double>::infinity() })
  {
    EXPECT_THROW(meshMassProperties(density, box), InvalidArgumentError) << density;
    EXPECT_THROW(particleMassProperties(density, box, 1000), InvalidArgumentError) << density;
  }
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(nan, box, "link 'wheel'")), std::exception, "link 'wheel': density");
  // Empty.
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(1.0, TriangleMesh(), "link 'e'")), std::exception,
                            "link 'e': mesh has no vertices");
  TriangleMesh no_triangles = box;
  no_triangles.triangles.clear();
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(1.0, no_triangles)), std::exception, "no triangles");
  EXPECT_THROW(meshMassProperties(1.0, TriangleMesh()), MeshLoadError);
  // Zero volume: a box squashed flat (closed, every triangle still used
  // twice) and a "pillow" of one triangle glued to its reverse.
  TriangleMesh flat = box;
  flat.vertices.row(2).setZero();
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(1.0, flat, "link 'flat'")), std::exception,
                            "link 'flat': closed mesh encloses no volume");
  EXPECT_THROW(particleMassProperties(1.0, flat, 1000), MeshLoadError);
  TriangleMesh pillow = makeMesh({ { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } }, { { 0, 1, 2 }, { 0, 2, 1 } });
  EXPECT_THROW(meshMassProperties(1.0, pillow), MeshLoadError);
  // Open: one triangle missing.
  TriangleMesh open = box;
  open.triangles.pop_back();
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(1.0, open)), std::exception, "not closed");
  EXPECT_THROW(particleMassProperties(1.0, open, 1000), MeshLoadError);
  // Inconsistently oriented: one triangle flipped.
  TriangleMesh flipped = box;
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(1.0, flipped)), std::exception, "not closed and consistently oriented");
  // Bad index and non-finite vertex.
  TriangleMesh bad_index = box;
  bad_index.triangles[5][2] = 8;
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(1.0, bad_index)), std::exception, "triangle 5 refers to vertex 8");
  TriangleMesh bad_vertex = box;
  bad_vertex.vertices(1, 6) = nan;
  DRB_EXPECT_THROWS_MESSAGE((meshMassProperties(1.0, bad_vertex)), std::exception, "vertex 6 is not finite");
  // Particles: zero target.
  EXPECT_THROW(particleMassProperties(1.0, box, 0), InvalidArgumentError);
}

TEST(MassPropertiesMesh, UnweldedDuplicateVerticesStillClosed)
{
  // Meshes from STL have one vertex per triangle corner: closedness must be
  // judged on positions, not indices.
  const TriangleMesh box = boxMesh(Eigen::Vector3d(1, 2, 3));
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<std::uint32_t, 3>> f;
  for (const auto& t : box.triangles)
  {
    const auto base = static_cast<std::uint32_t>(v.size());
    for (int k = 0; k < 3; ++k)
      v.push_back(box.vertices.col(t[k]));
    f.push_back({ base, base + 1, base + 2 });
  }
  const MassProperties soup = meshMassProperties(1.0, makeMesh(v, f));
  EXPECT_LT(relativeError(soup.inertia, boxMassProperties(1.0, Eigen::Vector3d(1, 2, 3)).inertia), ROUNDOFF_REL_TOL);
}

// ===========================================================================
// Ray casting and the particle sum, eq. (17)

TEST(MassPropertiesParticles, WindingNumberOnRaysThroughEdgesAndVertices)
{
  // Box: rays at y, z on the box's face planes run inside faces parallel to x
  // and through its edges and corners. The perturbed point (y + e, z + e^2)
  // decides: inside iff -b/2 <= y < b/2 and -c/2 <= z < c/2 (and x in [-a/2, a/2)).
  const Eigen::Vector3d size(1.0, 2.0, 4.0);
  const TriangleMesh box = boxMesh(size);
  for (double y : { -1.5, -1.0, -0.5, 0.0, 1.0, 1.5 })
    for (double z : { -3.0, -2.0, 0.0, 1.0, 2.0, 3.0 })
      for (double x : { -1.0, -0.5, 0.0, 0.5 })
      {
        const bool inside = -1.0 <= y && y < 1.0 && -2.0 <= z && z < 2.0 && -0.5 <= x && x < 0.5;
        EXPECT_EQ(meshWindingNumber(box, Eigen::Vector3d(x, y, z)), inside ? 1 : 0) << x << " " << y << " " << z;
        EXPECT_EQ(meshWindingNumber(reversed(box), Eigen::Vector3d(x, y, z)), inside ? -1 : 0);
      }
  // Icosphere: symmetric under x -> -x, so the ray through any vertex (or
  // edge midpoint) also leaves through its mirror. The point between them is
  // inside and must see exactly one exit; a point beyond sees none.
  const TriangleMesh sphere = icosphere(3, 1.0);
  int rays = 0;
  for (const auto& t : sphere.triangles)
  {
    const Eigen::Vector3d a = sphere.vertices.col(t[0]), b = sphere.vertices.col(t[1]);
    for (const Eigen::Vector3d& through : { a, Eigen::Vector3d(0.5 * (a + b)) })
    {
      if (std::abs(through.x()) < 0.25)
        continue;  // the mirror is within an edge (~0.16): the ray might run along the surface
      ++rays;
      EXPECT_EQ(meshWindingNumber(sphere, Eigen::Vector3d(0.0, through.y(), through.z())), 1) << through.transpose();
      EXPECT_EQ(meshWindingNumber(sphere, Eigen::Vector3d(-2.0, through.y(), through.z())), 0) << through.transpose();
      EXPECT_EQ(meshWindingNumber(sphere, Eigen::Vector3d(2.0, through.y(), through.z())), 0) << through.transpose();
    }
  }
  EXPECT_GT(rays, 500);
}

TEST(MassPropertiesParticles, MatchesBruteForceSumOverTheSameGrid)
{
  // The same grid (origin and cell from the result), inside test by the
  // half-spaces of a convex polyhedron, and eq. (17) summed point by point.
  std::mt19937 rng(2024);
  const TriangleMesh mesh = transformed(icosphere(2, 0.3), randomPose(rng, 10.0));
  const double density = 900.0;  // kg/m^3
  const ParticleMassProperties fast = particleMassProperties(density, mesh, 20000);
  const Eigen::Vector3d box_max = mesh.vertices.rowwise().maxCoeff();
  const Eigen::Vector3i count = ((box_max - fast.grid_origin) / fast.cell_size).array().ceil().cast<int>() + 1;
  std::vector<double> masses;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count.x(); ++i)
    for (int j = 0; j < count.y(); ++j)
      for (int k = 0; k < count.z(); ++k)
      {
        const Eigen::Vector3d p = fast.grid_origin + fast.cell_size * Eigen::Vector3d(i, j, k);
        bool inside = true;
        for (const auto& t : mesh.triangles)
        {
          const Eigen::Vector3d a = mesh.vertices.col(t[0]), b = mesh.vertices.col(t[1]), c = mesh.vertices.col(t[2]);
          if ((b - a).cross(c - a).dot(p - a) >= 0.0)
          {
            inside = false;
            break;
          }
        }
        if (inside)
        {
          masses.push_back(density * std::pow(fast.cell_size, 3));
          points.push_back(p);
        }
      }
  const MassProperties brute = particleSum(masses, points);
  EXPECT_EQ(fast.num_samples, masses.size());
  EXPECT_NEAR(fast.particle_mass, density * std::pow(fast.cell_size, 3), 1e-15 * fast.particle_mass);
  EXPECT_LT(relativeError(fast.mass_properties.mass, brute.mass), ROUNDOFF_REL_TOL);
  EXPECT_LT((fast.mass_properties.com - brute.com).norm(), COM_ABS_TOL);
  EXPECT_LT(relativeError(fast.mass_properties.inertia, brute.inertia), ROUNDOFF_REL_TOL);
}

TEST(MassPropertiesParticles, ConvergesToMeshIntegral)
{
  // Level-4 icosphere (r = 0.2 m) in 8 random poses (no alignment with the
  // grid). The staircase error of a grid of cell h counts ~A/h^2 boundary
  // cells with roughly independent errors: relative error ~ sqrt(A) h^2 / V
  // ~ N^(-2/3), i.e. /4.6 per decade of N. Over 6 independent sets of 8
  // poses the rms error fell by 2.6-8.5x per decade, and at N = 1e6 was at
  // most 3.9e-5 (mass), 6.6e-5 (COM / r) and 7.3e-5 (inertia).
  constexpr double MIN_DECADE_IMPROVEMENT = 2.0;  // rms over the poses
  constexpr double MASS_REL_TOL_1E6 = 1e-4;       // rms, relative
  constexpr double COM_REL_TOL_1E6 = 1.5e-4;      // rms, relative to the radius
  constexpr double INERTIA_REL_TOL_1E6 = 1.5e-4;  // rms, relative
  constexpr double SAMPLE_COUNT_REL_TOL = 0.02;   // N within 2 % of the target at >= 1e4
  constexpr int kPoses = 8;
  std::mt19937 rng(77);
  const double radius = 0.2, density = 1100.0;  // m, kg/m^3
  std::vector<TriangleMesh> meshes;
  std::vector<MassProperties> exact;
  for (int k = 0; k < kPoses; ++k)
  {
    meshes.push_back(transformed(icosphere(4, radius), randomPose(rng, 3.0)));
    exact.push_back(meshMassProperties(density, meshes.back()));
  }
  double previous[3] = { 0, 0, 0 };
  for (std::size_t target : { 1000u, 10000u, 100000u, 1000000u })
  {
    double rms[3] = { 0, 0, 0 };  // mass, COM, inertia
    for (int k = 0; k < kPoses; ++k)
    {
      const ParticleMassProperties p = particleMassProperties(density, meshes[k], target);
      const double errors[3] = { relativeError(p.mass_properties.mass, exact[k].mass),
                                 (p.mass_properties.com - exact[k].com).norm() / radius,
                                 relativeError(p.mass_properties.inertia, exact[k].inertia) };
      for (int e = 0; e < 3; ++e)
        rms[e] += errors[e] * errors[e] / kPoses;
      if (target >= 10000)
      {
        EXPECT_NEAR(static_cast<double>(p.num_samples), static_cast<double>(target), SAMPLE_COUNT_REL_TOL * target);
      }
    }
    for (double& e : rms)
      e = std::sqrt(e);
    std::printf("N = %zu: rms error mass %.3g, COM %.3g, inertia %.3g\n", target, rms[0], rms[1], rms[2]);
    for (int e = 0; target > 1000 && e < 3; ++e)
    {
      EXPECT_LT(rms[e] * MIN_DECADE_IMPROVEMENT, previous[e]) << "quantity " << e << " at N = " << target;
    }
    std::copy(rms, rms + 3, previous);
  }
  EXPECT_LT(previous[0], MASS_REL_TOL_1E6);
  EXPECT_LT(previous[1], COM_REL_TOL_1E6);
  EXPECT_LT(previous[2], INERTIA_REL_TOL_1E6);
}

TEST(MassPropertiesParticles, BunnyExactIntegralAgainstMillionParticles)
{
  // The Stanford bunny (closed, 27864 triangles); provenance in test/meshes/stanford/README.md.
  const std::string path = DRB_TEST_DATA_DIR "/meshes/stanford/bunny.obj";
  TriangleMesh bunny;
  std::string error;
  ASSERT_TRUE(readObj(path, &bunny, &error)) << "the bunny fixture is part of the repository: " << error;
  ASSERT_EQ(bunny.triangles.size(), 27864u);
  // Tolerances. The grid's staircase error is ~ sqrt(A) h^2 / V relative
  // (A/h^2 boundary cells, independent errors): with A = 0.0572 m^2,
  // V = 7.51e-4 m^3 and h = cbrt(V/1e6) = 9.1e-4 m, that is 2.6e-4. Measured
  // over this pose and 29 random rotations: max 1.9e-4 (mass), 4.6e-5 (COM /
  // diagonal), 3.0e-4 (inertia), all attained by this pose. Bounds ~2.5x that.
  constexpr double MASS_REL_TOL = 5e-4;     // relative
  constexpr double COM_REL_TOL = 1.5e-4;    // relative to the bounding-box diagonal
  constexpr double INERTIA_REL_TOL = 8e-4;  // relative
  constexpr double FAR_REL_TOL = 1e-10;     // relative, moved 1.5e3 m away (measured 5e-14)
  constexpr double SAMPLE_COUNT_REL_TOL = 1e-3;  // samples vs target (measured 1.9e-4)
  const double density = 1000.0;             // kg/m^3
  const MassProperties exact = meshMassProperties(density, bunny, "bunny");
  const auto start = std::chrono::steady_clock::now();
  const ParticleMassProperties particles = particleMassProperties(density, bunny, 1000000, "bunny");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double diagonal = (bunny.vertices.rowwise().maxCoeff() - bunny.vertices.rowwise().minCoeff()).norm();
  const double mass_error = relativeError(particles.mass_properties.mass, exact.mass);
  const double com_error = (particles.mass_properties.com - exact.com).norm() / diagonal;
  const double inertia_error = relativeError(particles.mass_properties.inertia, exact.inertia);
  std::printf("bunny: %zu samples in %.3f s; mass %.3g com %.3g inertia %.3g\n", particles.num_samples, seconds,
              mass_error, com_error, inertia_error);
  // Timing is reported, never asserted (machines are noisy): see docs/benchmarks.md.
  RecordProperty("particle_seconds_1e6", std::to_string(seconds));
  EXPECT_NEAR(static_cast<double>(particles.num_samples), 1e6, SAMPLE_COUNT_REL_TOL * 1e6);
  EXPECT_NEAR(particles.mass_properties.mass, particles.particle_mass * particles.num_samples, 1e-12 * exact.mass);
  EXPECT_LT(mass_error, MASS_REL_TOL);
  EXPECT_LT(com_error, COM_REL_TOL);
  EXPECT_LT(inertia_error, INERTIA_REL_TOL);
  // The exact integral does not care where the bunny is.
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Eigen::Vector3d(1e3, -1e3, 5e2);
  const MassProperties moved = meshMassProperties(density, transformed(bunny, far), "bunny far");
  EXPECT_LT(relativeError(moved.inertia, exact.inertia), FAR_REL_TOL);
}
