// Loading kinematic trees (~joints: model, docs/interface.md "Version 2"): which
// links form a body, its coordinates and limits, mimic joints, vertex ranges,
// warnings; and the textbook two-link arm's M(x) as a closed-form oracle.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../support/body_models.h"
#include "../support/expect_throws.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using namespace drb_test::urdf;

namespace
{
/// A 1-dof joint named `name` with an axis and limits.
std::string oneDofJoint(const std::string& name, const std::string& type, const std::string& parent,
                        const std::string& child, const std::string& origin, const std::string& axis,
                        const std::string& extra = "")
{
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent + "\"/><child link=\"" +
         child + "\"/>" + origin + "<axis xyz=\"" + axis + "\"/>" +
         (type == "continuous" ? "" : "<limit lower=\"-1.5\" upper=\"2\" effort=\"1\" velocity=\"1\"/>") + extra +
         "</joint>";
}

/// A point-like link: mass m at (lc, 0, 0) with inertia izz about its COM.
std::string rodLink(const std::string& name, double m, double lc, double izz)
{
  return link(name, "<inertial><origin xyz=\"" + std::to_string(lc) + " 0 0\"/><mass value=\"" +
                        std::to_string(m) + "\"/><inertia ixx=\"" + std::to_string(izz) +
                        "\" ixy=\"0\" ixz=\"0\" iyy=\"" + std::to_string(izz) + "\" iyz=\"0\" izz=\"" +
                        std::to_string(izz) + "\"/></inertial>" + collision(boxGeometry("0.1 0.1 0.1")));
}
}  // namespace

// Two links in a horizontal plane, joints about z: the closed form of any
// robotics textbook, M11 = I1 + I2 + m1 c1^2 + m2 (l1^2 + c2^2 + 2 l1 c2 cos x2),
// M12 = I2 + m2 (c2^2 + l1 c2 cos x2), M22 = I2 + m2 c2^2.
TEST(ArticulatedScene, TwoLinkArmMatchesTheClosedForm)
{
  const double m1 = 1.5, c1 = 0.25, I1 = 0.02, l1 = 0.6, m2 = 0.75, c2 = 0.375, I2 = 0.01;
  const std::string xml = robot(rodLink("upper", m1, c1, I1) + rodLink("fore", m2, c2, I2) +
                                oneDofJoint("shoulder", "continuous", "world", "upper", "", "0 0 1") +
                                oneDofJoint("elbow", "revolute", "upper", "fore",
                                            "<origin xyz=\"" + std::to_string(l1) + " 0 0\"/>", "0 0 1"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  ASSERT_EQ(scene.bodies.size(), 1u);
  ASSERT_FALSE(scene.bodies[0].closedFormKernels());
  const drb::BodyModel& arm = scene.bodies[0];
  ASSERT_EQ(arm.coordinates, 2u);
  for (const double x2 : { 0.0, 0.7, -1.4, 2.0 })
  {
    const double x[2] = { 0.3, x2 };
    const Eigen::MatrixXd M = drb_test::core_body::massMatrixAt(arm, x);
    const double M11 = I1 + I2 + m1 * c1 * c1 + m2 * (l1 * l1 + c2 * c2 + 2 * l1 * c2 * std::cos(x2));
    const double M12 = I2 + m2 * (c2 * c2 + l1 * c2 * std::cos(x2));
    const double M22 = I2 + m2 * c2 * c2;
    EXPECT_NEAR(M(0, 0), M11, 1e-15) << "x2 = " << x2;
    EXPECT_NEAR(M(0, 1), M12, 1e-15) << "x2 = " << x2;
    EXPECT_NEAR(M(1, 0), M12, 1e-15) << "x2 = " << x2;
    EXPECT_NEAR(M(1, 1), M22, 1e-15) << "x2 = " << x2;
  }
}

TEST(ArticulatedScene, FixedBaseTreeHasItsJointsInDocumentOrderWithLimits)
{
  // Document order of joints (b_joint before a_joint) differs from the tree and name order.
  const std::string xml =
      robot(rodLink("base", 1, 0, 0.1) + rodLink("a", 1, 0.1, 0.1) + rodLink("b", 1, 0.1, 0.1) +
            link("tool", inertial("0.5") + collision(boxGeometry("0.1 0.1 0.1"))) +
            oneDofJoint("b_joint", "prismatic", "base", "b", "<origin xyz=\"0 1 0\"/>", "0 0 2") +
            oneDofJoint("base_joint", "continuous", "world", "base", "<origin xyz=\"0 0 1\"/>", "0 0 1") +
            oneDofJoint("a_joint", "revolute", "base", "a", "<origin xyz=\"1 0 0\"/>", "0 1 0") +
            joint("fixed", "a", "tool", "<origin xyz=\"0.5 0 0\"/>"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  ASSERT_EQ(scene.bodies.size(), 1u);
  const drb::BodyModel& body = scene.bodies[0];
  ASSERT_FALSE(body.closedFormKernels());
  const drb::BodyModel& tree = body;
  EXPECT_EQ(body.name, "base");
  EXPECT_FALSE(tree.hasFreeRoot());
  EXPECT_EQ(tree.joint_names, (std::vector<std::string>{ "b_joint", "base_joint", "a_joint" }));
  EXPECT_EQ(tree.joint_lower, (std::vector<double>{ -1.5, -std::numeric_limits<double>::infinity(), -1.5 }));
  EXPECT_EQ(tree.joint_upper, (std::vector<double>{ 2, std::numeric_limits<double>::infinity(), 2 }));
  EXPECT_EQ(body.initial_x, Eigen::VectorXd::Zero(3));
  EXPECT_DOUBLE_EQ(body.mass(), 3.5);
  // Segments: parents first, then children in link document order (a before b).
  ASSERT_EQ(tree.segments.size(), 3u);
  EXPECT_EQ(tree.segments[0].link, "base");
  EXPECT_EQ(tree.segments[1].link, "a");
  EXPECT_EQ(tree.segments[2].link, "b");
  EXPECT_EQ(tree.dofs[tree.segments[1].first_dof].coordinate, 2);
  EXPECT_EQ(tree.dofs[tree.segments[2].first_dof].coordinate, 0);
  EXPECT_EQ(tree.segments[2].joint_type, drb::JointType::Prismatic);
  EXPECT_TRUE(tree.segments[2].axis.isApprox(Eigen::Vector3d::UnitZ())) << "the axis is normalised";
  // The tool is merged into segment a, whose mass it adds to.
  ASSERT_EQ(body.links.size(), 4u);
  EXPECT_EQ(body.links[2].name, "tool");
  EXPECT_EQ(body.links[2].segment, 1u);
  EXPECT_DOUBLE_EQ(tree.segments[1].inertia.mass, 1.5);
  // Each segment's box corners are contiguous, in segment order (a has the tool's too).
  EXPECT_EQ(tree.segments[1].vertex_begin, 8u);
  EXPECT_EQ(tree.segments[1].vertex_count, 16u);
  EXPECT_EQ(tree.segments[2].vertex_begin, 24u);
  EXPECT_EQ(tree.segmentOfVertex(7), 0u);
  EXPECT_EQ(tree.segmentOfVertex(8), 1u);
  EXPECT_EQ(tree.segmentOfVertex(23), 1u);
  EXPECT_EQ(tree.segmentOfVertex(24), 2u);

  // Joint values move the links: b slides 2 along z, a turns about y at (1, 0, 1).
  const double x[3] = { 0.25, 0.0, M_PI / 2 };
  const drb::BodyWorkspace<double> pose = drb_test::core_body::kinematicsAt(tree, x);
  EXPECT_TRUE(pose.p[2].isApprox(Eigen::Vector3d(0, 1, 1.25), 1e-15));
  const Eigen::Vector3d tool_tip = pose.R[1] * Eigen::Vector3d(0.5, 0, 0) + pose.p[1];
  EXPECT_NEAR((tool_tip - Eigen::Vector3d(1, 0, 0.5)).norm(), 0.0, 1e-15);
}

TEST(ArticulatedScene, MimicJointFollowsItsMasterAndAddsNoCoordinate)
{
  const std::string xml = robot(
      rodLink("palm", 1, 0, 0.1) + rodLink("left", 0.1, 0, 0.01) + rodLink("right", 0.1, 0, 0.01) +
      oneDofJoint("palm_joint", "revolute", "world", "palm", "", "0 0 1") +
      oneDofJoint("left_joint", "prismatic", "palm", "left", "", "0 1 0") +
      oneDofJoint("right_joint", "prismatic", "palm", "right", "", "0 -1 0",
                  "<mimic joint=\"left_joint\" multiplier=\"2\" offset=\"0.01\"/>"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  const drb::BodyModel& hand = scene.bodies.at(0);
  EXPECT_EQ(hand.joint_names, (std::vector<std::string>{ "palm_joint", "left_joint" }));
  ASSERT_EQ(hand.segments.size(), 3u);
  EXPECT_EQ(hand.dofs[hand.segments[2].first_dof].coordinate, 1);
  EXPECT_EQ(hand.dofs[hand.segments[2].first_dof].multiplier, 2.0);
  EXPECT_EQ(hand.segments[2].offset, 0.01);
  const double x[2] = { 0.0, 0.02 };
  const drb::BodyWorkspace<double> pose = drb_test::core_body::kinematicsAt(hand, x);
  EXPECT_NEAR(pose.p[2].y(), -(2 * 0.02 + 0.01), 1e-17);
}

TEST(ArticulatedScene, FloatingRootCarriesItsJointsAndAFloatingJointBelowStartsANewBody)
{
  const std::string xml =
      robot(rodLink("torso", 5, 0.1, 0.2) + rodLink("leg", 1, 0, 0.05) + rodLink("ball", 0.2, 0, 0.01) +
            floatingJoint("torso", "<origin xyz=\"0 0 1\" rpy=\"0.1 0.2 0.3\"/>") +
            oneDofJoint("hip", "revolute", "torso", "leg", "<origin xyz=\"0 0 -0.2\"/>", "0 1 0") +
            floatingJoint("ball", "", "leg"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  ASSERT_EQ(scene.bodies.size(), 2u);
  const drb::BodyModel& torso = scene.bodies[0];
  ASSERT_FALSE(torso.closedFormKernels());
  EXPECT_TRUE(torso.hasFreeRoot());
  EXPECT_EQ(torso.coordinates, 7u);
  EXPECT_NEAR(torso.initial_x[0], 0.1, 1e-15);
  EXPECT_NEAR(torso.initial_x[1], 0.2, 1e-15);
  EXPECT_NEAR(torso.initial_x[2], 0.3, 1e-15);
  EXPECT_EQ(torso.initial_x[6], 0.0);
  EXPECT_EQ(scene.bodies[1].name, "ball");
  EXPECT_TRUE(scene.bodies[1].closedFormKernels()) << "a floating body without joints is a version-1 free body";
}

TEST(ArticulatedScene, PlanarJointMakesAFreeBodyWithANote)
{
  const std::string xml = robot(rodLink("puck", 1, 0, 0.1) + oneDofJoint("slide", "planar", "world", "puck", "", "0 0 1"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  ASSERT_EQ(scene.bodies.size(), 1u);
  EXPECT_TRUE(scene.bodies[0].closedFormKernels());
  ASSERT_EQ(scene.unmodelled_joints.size(), 1u);
  EXPECT_NE(scene.unmodelled_joints[0].find("'slide' (planar)"), std::string::npos) << scene.unmodelled_joints[0];
}

TEST(ArticulatedScene, FreeObjectsLoadAsInVersionOne)
{
  const std::string xml = twoBodies();
  drb::SceneOptions free_joints;
  free_joints.joints = drb::JointHandling::Free;
  const drb::Scene model = drb::loadSceneFromUrdf(xml);
  const drb::Scene v1 = drb::loadSceneFromUrdf(xml, free_joints);
  ASSERT_EQ(model.bodies.size(), v1.bodies.size());
  for (std::size_t i = 0; i < v1.bodies.size(); ++i)
  {
    EXPECT_TRUE(model.bodies[i].closedFormKernels());
    EXPECT_EQ(model.bodies[i].initial_x, v1.bodies[i].initial_x);
    EXPECT_EQ(model.bodies[i].vertices, v1.bodies[i].vertices);
    EXPECT_EQ(model.bodies[i].segments[0].inertia.inertia, v1.bodies[i].segments[0].inertia.inertia);
    EXPECT_EQ(model.bodies[i].rootComOffset(), v1.bodies[i].rootComOffset());
  }
}

TEST(ArticulatedScene, ZeroAxisIsRefusedNamingTheJoint)
{
  const std::string xml = robot(rodLink("arm", 1, 0, 0.1) + oneDofJoint("bad", "revolute", "world", "arm", "", "0 0 0"));
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(xml), drb::SceneDescriptionError, "joint 'bad': <axis>");
}

TEST(ArticulatedScene, CoordinateThatMovesNoMassWarnsAndStrictRefuses)
{
  const std::string xml = robot(rodLink("arm", 1, 0, 0.1) + link("tip", collision(boxGeometry("0.1 0.1 0.1"))) +
                                oneDofJoint("arm_joint", "revolute", "world", "arm", "", "0 0 1") +
                                oneDofJoint("tip_joint", "revolute", "arm", "tip", "", "1 0 0"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  bool warned = false;
  for (const std::string& warning : scene.warnings)
    warned |= warning.find("joint 'tip_joint' of body 'arm': moves no mass") != std::string::npos;
  EXPECT_TRUE(warned);
  drb::SceneOptions strict;
  strict.strict_inertia = true;
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdf(xml, strict), drb::InvalidInertiaError, "link 'tip': no <inertial>");
}

// The all-vertex paths (blocked moments, segment by segment) against the
// index-list paths (vertex by vertex), and backprop against J^T g.
TEST(ArticulatedScene, AllVertexPathsAgreeWithIndexListsAndJTransposeG)
{
  const std::string xml =
      robot(rodLink("torso", 5, 0.1, 0.2) + rodLink("leg", 1, 0, 0.05) + rodLink("foot", 0.5, 0.05, 0.01) +
            floatingJoint("torso", "<origin xyz=\"0 0 1\"/>") +
            oneDofJoint("hip", "revolute", "torso", "leg", "<origin xyz=\"0 0 -0.2\"/>", "0 1 0") +
            oneDofJoint("ankle", "prismatic", "leg", "foot", "<origin xyz=\"0 0 -0.4\"/>", "1 0 1"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  const drb::BodyModel& body = scene.bodies.at(0);
  const std::size_t n = static_cast<std::size_t>(body.vertices.cols()), dofs = body.coordinates;
  ASSERT_EQ(dofs, 8u);
  const double x[8] = { 0.3, -0.4, 1.1, 0.5, -0.2, 0.9, 0.7, 0.05 };
  std::vector<std::uint32_t> every(n);
  std::vector<double> g(3 * n);
  for (std::size_t v = 0; v < n; ++v)
  {
    every[v] = static_cast<std::uint32_t>(v);
    for (int i = 0; i < 3; ++i)
      g[3 * v + i] = std::sin(1.0 + 3.0 * v + i);
  }
  std::vector<double> p_all(3 * n), J_all(3 * dofs * n), p_list(3 * n), J_list(3 * dofs * n);
  drb_test::core_body::vertexJacobiansAt(body, false, {}, x, p_all.data(), J_all.data());
  drb_test::core_body::vertexJacobiansAt(body, false, every, x, p_list.data(), J_list.data());
  EXPECT_EQ(p_all, p_list);
  EXPECT_EQ(J_all, J_list);
  std::vector<double> grad_all(dofs), grad_list(dofs);
  drb_test::core_body::backpropAt(body, {}, g.data(), x, grad_all.data());
  drb_test::core_body::backpropAt(body, every, g.data(), x, grad_list.data());
  for (std::size_t c = 0; c < dofs; ++c)
  {
    double jtg = 0.0, scale = 0.0;
    for (std::size_t v = 0; v < n; ++v)
      for (std::size_t i = 0; i < 3; ++i)
      {
        jtg += J_all[3 * dofs * v + dofs * i + c] * g[3 * v + i];
        scale += std::abs(J_all[3 * dofs * v + dofs * i + c] * g[3 * v + i]);
      }
    EXPECT_NEAR(grad_all[c], jtg, 1e-14 * scale) << "coordinate " << c;
    EXPECT_NEAR(grad_list[c], jtg, 1e-14 * scale) << "coordinate " << c;
  }
}

// Links A, B, C, D in document order, B and C children of A, D a child of B:
// segments (and vertex ranges) follow the document, A B C D, not depth first
// (A B D C). D has no geometry: the last segment is empty, which every
// all-vertex path must take.
TEST(ArticulatedScene, SegmentsFollowTheDocumentWithParentsFirst)
{
  const std::string xml =
      robot(rodLink("A", 1, 0, 0.1) + rodLink("B", 1, 0, 0.1) + rodLink("C", 1, 0, 0.1) +
            link("D", inertial("0.5")) + oneDofJoint("A_joint", "revolute", "world", "A", "", "0 0 1") +
            oneDofJoint("B_joint", "revolute", "A", "B", "<origin xyz=\"1 0 0\"/>", "0 0 1") +
            oneDofJoint("C_joint", "revolute", "A", "C", "<origin xyz=\"0 1 0\"/>", "0 0 1") +
            oneDofJoint("D_joint", "revolute", "B", "D", "<origin xyz=\"1 0 0\"/>", "0 0 1"));
  const drb::Scene scene = drb::loadSceneFromUrdf(xml);
  const drb::BodyModel& tree = scene.bodies.at(0);
  ASSERT_EQ(tree.segments.size(), 4u);
  EXPECT_EQ(tree.segments[1].link, "B");
  EXPECT_EQ(tree.segments[2].link, "C");
  EXPECT_EQ(tree.segments[3].link, "D");
  EXPECT_EQ(tree.segments[3].parent, 1);
  EXPECT_EQ(tree.segments[3].vertex_count, 0u);
  const double x[4] = { 0.1, 0.2, 0.3, 0.4 };
  const std::vector<double> g(3 * static_cast<std::size_t>(tree.vertices.cols()), 1.0);
  std::vector<double> gradient(4);
  drb_test::core_body::backpropAt(tree, {}, g.data(), x, gradient.data());
  EXPECT_EQ(gradient[3], 0.0) << "D moves no vertex";
  EXPECT_TRUE(Eigen::Map<const Eigen::Vector4d>(gradient.data()).allFinite());
}

// A finite x whose link poses overflow (a slider at 1e308 plus its origin)
// is refused by set_state and joint_states alike, naming the body; the
// state is unchanged.
TEST(ArticulatedScene, StatesWhoseLinkPosesOverflowAreRefused)
{
  const std::string xml = robot(rodLink("rail", 1, 0, 0.1) + rodLink("cart", 1, 0, 0.1) +
                                oneDofJoint("rail_joint", "revolute", "world", "rail", "", "0 0 1") +
                                oneDofJoint("cart_joint", "prismatic", "rail", "cart",
                                            "<origin xyz=\"1e308 0 0\"/>", "1 0 0"));
  const drb::SceneQueries queries(drb::loadSceneFromUrdf(xml));
  const drb::SceneState start = queries.initialState();
  drb::NamedState huge{ "rail", Eigen::Vector2d(0.0, 1e308) };
  DRB_EXPECT_THROWS_MESSAGE(queries.applyStates(start, { huge }), drb::InvalidArgumentError,
                            "states[0].q (body 'rail'): the link poses of body 'rail' overflow");
  std::vector<std::string> unknown;
  DRB_EXPECT_THROWS_MESSAGE(queries.applyJointPositions(start, { "cart_joint" }, { 1e308 }, unknown),
                            drb::InvalidArgumentError, "position: the link poses of body 'rail' overflow");
  const drb::SceneState moved = queries.applyJointPositions(start, { "cart_joint" }, { 2.0 }, unknown);
  EXPECT_EQ(moved[0][1], 2.0);
}

// A vertex answer is 3 (1 + d) doubles per vertex and configuration: with
// d = 8 the vertex limit alone would let 113 M doubles through; the answer
// limit (RequestLimits::kMaxVertexAnswerDoubles) refuses it before anything
// is allocated.
TEST(ArticulatedScene, VertexRequestsOverTheWorkLimitAreRefused)
{
  const std::string xml =
      robot(rodLink("torso", 5, 0.1, 0.2) + rodLink("leg", 1, 0, 0.05) + rodLink("foot", 0.5, 0.05, 0.01) +
            floatingJoint("torso") + oneDofJoint("hip", "revolute", "torso", "leg", "", "0 1 0") +
            oneDofJoint("ankle", "prismatic", "leg", "foot", "", "1 0 0"));
  const drb::SceneQueries queries(drb::loadSceneFromUrdf(xml));
  const std::size_t n = queries.scene().bodies[0].vertexCount(), dofs = queries.dofs(0);
  ASSERT_EQ(dofs, 8u);
  const std::size_t configurations = drb::RequestLimits::kMaxVertices / n;  // within the vertex limit
  const std::vector<double> q(configurations * dofs, 0.0);
  std::vector<double> positions, jacobians;
  DRB_EXPECT_THROWS_MESSAGE(queries.vertexJacobians(queries.initialState(), "torso", {}, q, positions, jacobians),
                            drb::InvalidArgumentError, "more than the limit of 88080384");
  EXPECT_TRUE(positions.empty() && jacobians.empty());
}
