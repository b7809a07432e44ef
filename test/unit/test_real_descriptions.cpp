// What real robot descriptions contain and the contract loads (docs/interface.md,
// "Version 2"): massless frames and links without <inertial> merge as
// massless; implausible inertia warns, naming the link, and is refused only
// with strict_inertia; undefined inertia is always refused; a body that
// starts at gimbal lock warns; Collada files are placed as rviz places them.
// Expected values are worked out by hand in the comments.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mesh_loader.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../support/expect_throws.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using namespace drb_test::urdf;

namespace
{
constexpr double kLengthTolerance = 1e-12;  // m
/// [m] assimp stores positions as float32: one float ulp at 0.1 m is 7.5e-9 m.
constexpr double kFloat32LengthTolerance = 2e-8;
const std::string kTestMeshDir = std::string(DRB_TEST_DATA_DIR) + "/meshes";

/// Body "b" (floating) with `b_inner` in its link, and a link "tool" fixed to
/// it at x = 1 m with `tool_inner`.
std::string bodyWithTool(const std::string& b_inner, const std::string& tool_inner)
{
  return robot(link("b", b_inner) + link("tool", tool_inner) + floatingJoint("b") +
               joint("fixed", "b", "tool", "<origin xyz=\"1 0 0\"/>"));
}

drb::SceneOptions strict()
{
  drb::SceneOptions options;
  options.strict_inertia = true;
  return options;
}

bool anyWarningHas(const drb::Scene& scene, const std::string& fragment)
{
  for (const std::string& warning : scene.warnings)
    if (warning.find(fragment) != std::string::npos)
      return true;
  return false;
}

std::string allWarnings(const drb::Scene& scene)
{
  std::string text;
  for (const std::string& warning : scene.warnings)
    text += "\n  " + warning;
  return text.empty() ? " (none)" : text;
}
}  // namespace

TEST(RealDescriptions, ZeroMassToolFrameMergesAsMassless)
{
  // b: 2 kg at its origin; tool: 0 kg (and a zero tensor) at x = 1 m. The
  // body keeps b's mass, COM and inertia; the tool frame still gets its pose.
  const std::string xml = bodyWithTool(inertial("2"), inertial("0", diagonalInertia("0", "0", "0")));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  ASSERT_EQ(scene.bodies.size(), 1u);
  const drb::BodyModel& body = scene.bodies[0];
  EXPECT_EQ(body.mass(), 2.0);
  EXPECT_TRUE(body.rootComOffset().isZero(0.0));
  EXPECT_NEAR((body.segments[0].inertia.inertia - 0.1 * Eigen::Matrix3d::Identity()).norm(), 0.0, kLengthTolerance);
  ASSERT_EQ(body.links.size(), 2u);
  EXPECT_EQ(body.links[1].name, "tool");
  EXPECT_EQ(body.links[1].mass_properties.mass, 0.0);
  EXPECT_TRUE(anyWarningHas(scene, "link 'tool' <inertial>: mass must be > 0 kg, got 0; merged as massless"))
      << allWarnings(scene);

  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(xml, strict()), drb::InvalidInertiaError,
                            "link 'tool' <inertial>: mass must be > 0 kg, got 0");
}

TEST(RealDescriptions, LinkWithoutInertialMergesAsMasslessAndKeepsItsVertices)
{
  // tool has a 2 x 2 x 2 box at x = 1 m and no <inertial>: 8 more vertices,
  // no mass. b's box is 1 x 1 x 1 at its origin.
  const std::string xml =
      bodyWithTool(inertial("2") + collision(boxGeometry("1 1 1")), collision(boxGeometry("2 2 2")));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  const drb::BodyModel& body = scene.bodies[0];
  EXPECT_EQ(body.mass(), 2.0);
  ASSERT_EQ(body.vertices.cols(), 16);
  EXPECT_EQ(body.links[0].new_vertex_count, 8u);
  EXPECT_EQ(body.links[1].new_vertex_count, 8u);
  // tool's last corner (+1, +1, +1) in its frame is (2, 1, 1) in b's frame (the COM).
  EXPECT_TRUE(body.vertices.col(15).isApprox(Eigen::Vector3d(2, 1, 1), kLengthTolerance));
  EXPECT_TRUE(anyWarningHas(scene, "link 'tool': no <inertial> (set ~density")) << allWarnings(scene);
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(xml, strict()), drb::InvalidInertiaError,
                            "link 'tool': no <inertial>");
}

TEST(RealDescriptions, BodyWithoutAnyMassLoadsWithAZeroMassMatrix)
{
  // Only geometry (as urdf_tutorial's 06-flexible.urdf): the COM is the link
  // origin, M(q) = 0, and the warning points at ~density.
  const std::string xml = oneBody(collision(boxGeometry("1 1 1")), "<origin xyz=\"0 0 2\"/>");
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  const drb::BodyModel& body = scene.bodies[0];
  EXPECT_EQ(body.mass(), 0.0);
  EXPECT_TRUE(body.rootComOffset().isZero(0.0));
  EXPECT_TRUE(body.segments[0].inertia.inertia.isZero(0.0));
  EXPECT_EQ(body.initial_x[5], 2.0);
  EXPECT_TRUE(anyWarningHas(scene, "body 'b': no mass in its link or merged links, so M(q) = 0"))
      << allWarnings(scene);
  const drb::SceneQueries queries(scene);
  const drb::MassMatrixAnswer answer = queries.massMatrices(queries.initialState(), { "b" }, {}, true);
  for (double entry : answer.mass_matrices)
    EXPECT_EQ(entry, 0.0);
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(xml, strict()), drb::InvalidInertiaError, "link 'b': no <inertial>");
}

TEST(RealDescriptions, ImplausibleInertiaWarnsAndStrictRefuses)
{
  // (1, 1, 3) breaks I1 + I2 >= I3; (0, 1, 1) has a zero principal moment.
  const std::string triangle = oneBody(inertial("1", diagonalInertia("1", "1", "3")));
  const drb::Scene scene = drb::loadSceneFromUrdf(triangle);
  EXPECT_EQ(scene.bodies[0].segments[0].inertia.inertia(2, 2), 3.0);
  EXPECT_TRUE(anyWarningHas(scene, "link 'b' <inertial>: principal moments break the triangle inequality"))
      << allWarnings(scene);
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(triangle, strict()), drb::InvalidInertiaError,
                            "triangle inequality");

  const std::string rod = oneBody(inertial("1", diagonalInertia("0", "1", "1")));
  const drb::Scene rod_scene = drb::loadSceneFromUrdf(rod);
  EXPECT_TRUE(anyWarningHas(rod_scene, "link 'b' <inertial>: inertia must be positive-definite"))
      << allWarnings(rod_scene);
  EXPECT_TRUE(anyWarningHas(rod_scene, "body 'b': a principal moment of its inertia is 0, so M(q) is singular"))
      << allWarnings(rod_scene);
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(rod, strict()), drb::InvalidInertiaError, "positive-definite");
}

TEST(RealDescriptions, UndefinedInertiaIsAlwaysRefused)
{
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(oneBody(inertial("-1"))), drb::InvalidInertiaError,
                            "link 'b' <inertial>: mass must be > 0 kg, got -1");
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(oneBody(inertial("1", diagonalInertia("-0.1", "1", "1")))),
                            drb::InvalidInertiaError, "smallest principal moment is -0.1");
}

TEST(RealDescriptions, BodyStartingAtGimbalLockWarns)
{
  const auto floating_pitched = [](const std::string& pitch) {
    return oneBody(inertial("1"), "<origin rpy=\"0 " + pitch + " 0\"/>");
  };
  const drb::Scene locked = drb::loadSceneFromUrdf(floating_pitched("1.5707963267948966"));
  EXPECT_TRUE(anyWarningHas(locked, "body 'b' (joint 'b_joint', floating) starts at gimbal lock")) << allWarnings(locked);
  // 1e-5 rad away is outside the 1e-6 rad band: no warning.
  EXPECT_TRUE(drb::loadSceneFromUrdf(floating_pitched("1.5707863267948966")).warnings.empty());
  // Gimbal lock is a property of the coordinates, not of the inertia: strict still loads it.
  EXPECT_NO_THROW(drb::loadSceneFromUrdf(floating_pitched("-1.5707963267948966"), strict()));
}

TEST(RealDescriptions, ColladaIsPlacedAsRvizPlacesIt)
{
  // tetra_z_up_cm.dae: Z_UP, unit 0.01 m, node translate (10, 0, 0) then
  // rotate 90 deg about z. Corner (1, 2, 3) cm -> Rz(90) (1, 2, 3) = (-2, 1, 3),
  // + (10, 0, 0) = (8, 1, 3) cm = (0.08, 0.01, 0.03) m. With the up axis
  // applied (assimp's default) it would be (0.08, 0.03, -0.01) m.
  const drb::TriangleMesh mesh = drb::loadMeshFile(kTestMeshDir + "/tetra_z_up_cm.dae");
  ASSERT_EQ(mesh.vertices.cols(), 4);
  const Eigen::Vector3d expected[] = { { 0.10, 0.0, 0.0 }, { 0.10, 0.04, 0.0 }, { 0.08, 0.01, 0.03 }, { 0.05, 0.0, 0.0 } };
  for (const Eigen::Vector3d& corner : expected)
  {
    double nearest = INFINITY;
    for (Eigen::Index v = 0; v < mesh.vertices.cols(); ++v)
      nearest = std::min(nearest, (mesh.vertices.col(v) - corner).norm());
    EXPECT_LT(nearest, kFloat32LengthTolerance) << "corner " << corner.transpose();
  }
}
