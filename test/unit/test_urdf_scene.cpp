// URDF -> scene: bodies, merged fixed links, static links, inertial frames,
// geometry sources, and load errors. Expected values are worked out by hand
// in the comments, not computed with the library.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../support/expect_throws.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using namespace drb_test::urdf;

namespace
{
constexpr double kLengthTolerance = 1e-12;   // m
constexpr double kInertiaTolerance = 1e-12;  // kg m^2
constexpr double kAngleTolerance = 1e-12;    // rad
const std::string kTestMeshDir = std::string(DRB_TEST_DATA_DIR) + "/meshes";
}  // namespace

TEST(UrdfScene, ComOffsetAndRotatedInertialFrame)
{
  // Inertial frame at (0.1, 0.2, 0.3) rotated by yaw pi/2: diag(1, 2, 3) in
  // the inertial frame is diag(2, 1, 3) in link axes (x and y swap).
  const std::string xml = robot(
      "<link name=\"body\"><inertial><origin xyz=\"0.1 0.2 0.3\" rpy=\"0 0 1.5707963267948966\"/>"
      "<mass value=\"2\"/><inertia ixx=\"1\" iyy=\"2\" izz=\"3\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>"
      "<collision><origin xyz=\"0.1 0.2 0.3\"/><geometry><box size=\"0.2 0.4 0.6\"/></geometry></collision>"
      "</link>" +
      floatingJoint("body", "<origin xyz=\"1 2 3\"/>"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  ASSERT_EQ(scene.bodies.size(), 1u);
  const drb::BodyModel& body = scene.bodies[0];
  EXPECT_EQ(scene.fixed_frame, "world");
  EXPECT_EQ(body.name, "body");
  EXPECT_DOUBLE_EQ(body.mass(), 2.0);
  EXPECT_TRUE(body.rootComOffset().isApprox(Eigen::Vector3d(0.1, 0.2, 0.3), kLengthTolerance));
  EXPECT_NEAR((body.segments[0].inertia.inertia - Eigen::Vector3d(2, 1, 3).asDiagonal().toDenseMatrix()).norm(), 0.0,
              kInertiaTolerance);
  // The box is centred on the COM, so its corners are (+-0.1, +-0.2, +-0.3) in the body frame.
  ASSERT_EQ(body.vertices.cols(), 8);
  EXPECT_TRUE(body.vertices.col(0).isApprox(Eigen::Vector3d(-0.1, -0.2, -0.3), kLengthTolerance));
  EXPECT_TRUE(body.vertices.col(7).isApprox(Eigen::Vector3d(0.1, 0.2, 0.3), kLengthTolerance));
  // q = (0, 0, 0, joint origin + COM offset).
  const drb::Vector6<double> expected = (drb::Vector6<double>() << 0, 0, 0, 1.1, 2.2, 3.3).finished();
  EXPECT_NEAR((scene.bodies[0].initial_x - expected).norm(), 0.0, kLengthTolerance);
}

TEST(UrdfScene, MergesFixedLinksTransitivelyWithParallelAxisInertia)
{
  // base (1 kg at its origin) + arm (1 kg, 1 m along x) + massless tip:
  //   mass 2 kg, COM (0.5, 0, 0);
  //   I = 2 * diag(0.1) + 2 * 1 kg * diag(0, 0.25, 0.25) = diag(0.2, 0.7, 0.7).
  const std::string xml = robot(link("base", inertial()) + link("arm", inertial()) + link("tip") +
                                floatingJoint("base", "<origin xyz=\"0 0 1\" rpy=\"0 0 0.5\"/>") +
                                joint("fixed", "base", "arm", "<origin xyz=\"1 0 0\"/>") +
                                joint("fixed", "arm", "tip", "<origin xyz=\"0 1 0\" rpy=\"0.3 0 0\"/>"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  ASSERT_EQ(scene.bodies.size(), 1u);
  const drb::BodyModel& body = scene.bodies[0];
  EXPECT_DOUBLE_EQ(body.mass(), 2.0);
  EXPECT_TRUE(body.rootComOffset().isApprox(Eigen::Vector3d(0.5, 0, 0), kLengthTolerance));
  const Eigen::Matrix3d& inertia = body.segments[0].inertia.inertia;
  EXPECT_NEAR((inertia - Eigen::Vector3d(0.2, 0.7, 0.7).asDiagonal().toDenseMatrix()).norm(), 0.0, kInertiaTolerance);
  ASSERT_EQ(body.links.size(), 3u);
  EXPECT_EQ(body.links[0].name, "base");
  EXPECT_EQ(body.links[1].name, "arm");
  EXPECT_EQ(body.links[2].name, "tip");
  EXPECT_TRUE(body.links[2].pose_in_segment_link.translation().isApprox(Eigen::Vector3d(1, 1, 0), kLengthTolerance));
  // Yaw 0.5 from the joint; the COM sits 0.5 m along the body's rotated x axis.
  EXPECT_NEAR(body.initial_x[drb::PSI], 0.5, kAngleTolerance);
  EXPECT_NEAR(body.initial_x[drb::TX], 0.5 * std::cos(0.5), kLengthTolerance);
  EXPECT_NEAR(body.initial_x[drb::TY], 0.5 * std::sin(0.5), kLengthTolerance);
  EXPECT_NEAR(body.initial_x[drb::TZ], 1.0, kLengthTolerance);
  EXPECT_TRUE(scene.unmodelled_joints.empty());
}

TEST(UrdfScene, StaticLinksAndUnmodelledJointsWhenJointsAreFree)
{
  const std::string xml =
      robot(link("table", collision(boxGeometry("1 1 1"))) + link("box", inertial()) + link("flap", inertial()) +
            joint("fixed", "world", "table", "<origin xyz=\"0 0 0.5\"/>") +
            floatingJoint("box", "<origin xyz=\"0 0 1\"/>", "table") +
            "<joint name=\"hinge\" type=\"revolute\"><parent link=\"box\"/><child link=\"flap\"/>"
            "<origin xyz=\"0 0 0.25\"/><axis xyz=\"1 0 0\"/>"
            "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>");
  drb::SceneOptions free_joints;
  free_joints.joints = drb::JointHandling::Free;
  const drb::Scene scene = drb::loadSceneFromUrdf(xml, free_joints);
  ASSERT_EQ(scene.static_links.size(), 1u);
  EXPECT_EQ(scene.static_links[0].name, "table");
  EXPECT_TRUE(scene.static_links[0].pose_in_fixed_frame.translation().isApprox(Eigen::Vector3d(0, 0, 0.5)));
  ASSERT_EQ(scene.bodies.size(), 2u);
  EXPECT_EQ(scene.bodies[0].name, "box");
  EXPECT_EQ(scene.bodies[1].name, "flap");
  EXPECT_NEAR(scene.bodies[0].initial_x[drb::TZ], 1.5, kLengthTolerance);
  EXPECT_NEAR(scene.bodies[1].initial_x[drb::TZ], 1.75, kLengthTolerance);
  ASSERT_EQ(scene.unmodelled_joints.size(), 1u);
  EXPECT_NE(scene.unmodelled_joints[0].find("hinge"), std::string::npos);

  // States can be expressed in a static link instead of the root.
  drb::SceneOptions in_table = free_joints;
  in_table.fixed_frame = "table";
  const drb::Scene relative = drb::loadSceneFromUrdf(xml, in_table);
  EXPECT_NEAR(relative.bodies[0].initial_x[drb::TZ], 1.0, kLengthTolerance);
  ASSERT_EQ(relative.static_links.size(), 1u);
  EXPECT_EQ(relative.static_links[0].name, "world");
  EXPECT_NEAR(relative.static_links[0].pose_in_fixed_frame.translation().z(), -0.5, kLengthTolerance);

  // Only the listed bodies are modelled.
  drb::SceneOptions only_flap = free_joints;
  only_flap.bodies = { "flap" };
  const drb::Scene subset = drb::loadSceneFromUrdf(xml, only_flap);
  ASSERT_EQ(subset.bodies.size(), 1u);
  EXPECT_EQ(subset.bodies[0].name, "flap");
}

TEST(UrdfScene, MeshScaleAndOriginFromAFile)
{
  // Tetrahedron corners (0,0,0), (1,0,0), (0,1,0), (0,0,1), scaled by (2, 3, 4)
  // -> (0,0,0), (2,0,0), (0,3,0), (0,0,4); yaw pi/2 maps (x, y, z) to (-y, x, z)
  // -> (0,0,0), (0,2,0), (-3,0,0), (0,0,4); then + (0.5, 0, 0). Mesh order is
  // the order of first use by the faces (first face: 1 3 2).
  const std::string origin = "<origin xyz=\"0.5 0 0\" rpy=\"0 0 1.5707963267948966\"/>";
  const std::string mesh = meshGeometry("file://" + kTestMeshDir + "/tetrahedron.obj", "2 3 4");
  const std::string xml = robot(link("tet", inertial() + collision(mesh, origin)) + floatingJoint("tet"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  const Eigen::Matrix3Xd& v = scene.bodies[0].vertices;
  ASSERT_EQ(v.cols(), 4);
  EXPECT_TRUE(v.col(0).isApprox(Eigen::Vector3d(0.5, 0, 0), kLengthTolerance));
  EXPECT_TRUE(v.col(1).isApprox(Eigen::Vector3d(-2.5, 0, 0), kLengthTolerance));
  EXPECT_TRUE(v.col(2).isApprox(Eigen::Vector3d(0.5, 2, 0), kLengthTolerance));
  EXPECT_TRUE(v.col(3).isApprox(Eigen::Vector3d(0.5, 0, 4), kLengthTolerance));
}

TEST(UrdfScene, PackageUrisAndVisualGeometry)
{
  const std::string xml = robot("<link name=\"b\">" + inertial() +
                                "<visual><geometry><mesh "
                                "filename=\"package://test_pkg/meshes/box_2x1x0.5.stl\"/></geometry></visual>"
                                "<collision><geometry><sphere radius=\"1\"/></geometry></collision></link>" +
                                floatingJoint("b"));
  drb::SceneOptions options;
  options.find_package = [](const std::string& package) {
    return package == "test_pkg" ? std::string(DRB_TEST_DATA_DIR) : std::string();
  };
  // Collision (the default) gives the documented 114-vertex sphere.
  EXPECT_EQ(drb::loadSceneFromUrdf(xml, options).bodies[0].vertices.cols(), 114);
  // Visual gives the STL box; its 36 triangle corners join into 8 vertices.
  options.geometry = drb::GeometrySource::Visual;
  EXPECT_EQ(drb::loadSceneFromUrdf(xml, options).bodies[0].vertices.cols(), 8);

  drb::SceneOptions no_resolver;
  no_resolver.geometry = drb::GeometrySource::Visual;
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(xml, no_resolver), drb::MeshLoadError,
                            "cannot find package 'test_pkg'");
}

TEST(UrdfScene, InertiaFromDensity)
{
  // Box 1 x 2 x 3 m at 1000 kg/m^3: m = 6000 kg,
  // I = m/12 diag(2^2 + 3^2, 1^2 + 3^2, 1^2 + 2^2) = diag(6500, 5000, 2500) kg m^2.
  const std::string xml = robot(
      "<link name=\"b\"><collision><geometry><box size=\"1 2 3\"/></geometry></collision></link>" +
      floatingJoint("b"));
  drb::SceneOptions options;
  options.density = 1000.0;
  const drb::Scene scene = drb::loadSceneFromUrdf(xml, options);
  EXPECT_NEAR(scene.bodies[0].mass(), 6000.0, 1e-9);
  const Eigen::Matrix3d& inertia = scene.bodies[0].segments[0].inertia.inertia;
  EXPECT_NEAR((inertia - Eigen::Vector3d(6500, 5000, 2500).asDiagonal().toDenseMatrix()).norm(), 0.0, 1e-8);
}

TEST(UrdfScene, RejectsUnusableDescriptions)
{
  const std::string ok_body = link("b", inertial()) + floatingJoint("b");
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf("<robot name=\"r\"><link name=\"world\"></robot>"),
                            drb::SceneDescriptionError, "malformed XML");
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(robot("")), drb::SceneDescriptionError, "no body");
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(oneBody(inertial("-1"))), drb::InvalidInertiaError,
                            "link 'b' <inertial>: mass must be > 0");
  const std::string missing_mesh = collision(meshGeometry("/nonexistent/missing.stl"));
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(oneBody(inertial() + missing_mesh)), drb::MeshLoadError,
                            "/nonexistent/missing.stl");
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(oneBody(inertial() + collision(boxGeometry("1 0 1")))),
                            drb::SceneDescriptionError, "box size y must be finite and > 0");
  drb::SceneOptions unknown;
  unknown.bodies = { "nope" };
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(robot(ok_body), unknown), drb::SceneDescriptionError,
                            "unknown body 'nope'");
  drb::SceneOptions bad_frame;
  bad_frame.fixed_frame = "b";
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(robot(ok_body), bad_frame), drb::SceneDescriptionError,
                            "fixed_frame: 'b'");
}
