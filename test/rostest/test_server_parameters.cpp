// Node parameters that change the scene, each run by its own .test on a
// fresh node:
//   - ~bodies (bodies_subset.test: [roller, tet] of the fixture scene): only
//     those bodies are served and published on tf;
//   - ~geometry:=visual (geometry_visual.test): vertices from <visual>
//     geometry, <collision> for a link that has none;
//   - ~density (density.test: test/urdf/density_scene.urdf at 2700 kg/m^3):
//     mass properties of links without <inertial> from their closed geometry.
// The oracles never call the library: fixture_scene.h (the fixture URDF
// transcribed, parallel-axis composites, the documented tessellations) and
// the closed forms of solid primitives and of a right tetrahedron below.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tf2_msgs/TFMessage.h>

#include "../support/expect_throws.h"
#include "server_under_test.h"

namespace drb_rostest
{
namespace
{
/// Masses and inertias against the oracle, relative to the largest entry:
/// both sides round differently, so a few thousand ulp of headroom.
constexpr double kRelativeTolerance = 1e-12;  // 1
/// COM offsets and vertices (sizes of at most 3 m).
constexpr double kLengthTolerance = 1e-12;  // m
/// How long to wait for tf messages to arrive (a wait, never an assertion on time).
const double kTimeout = 30.0;  // s

double maxAbs(const Eigen::MatrixXd& m)
{
  return m.size() ? m.cwiseAbs().maxCoeff() : 0.0;
}

/// Index of `name` in a get_bodies answer; fails the test when it is absent.
std::size_t indexOf(const diff_rigid_body_ros::Bodies& bodies, const std::string& name)
{
  const auto found = std::find(bodies.names.begin(), bodies.names.end(), name);
  if (found == bodies.names.end())
    throw std::runtime_error("get_bodies does not list '" + name + "'");
  return static_cast<std::size_t>(found - bodies.names.begin());
}

/// get_bodies' mass [kg], COM offset (link frame) [m] and inertia (about the
/// COM, body axes) [kg m^2] of `name` against the expected values.
void expectMassProperties(const diff_rigid_body_ros::Bodies& bodies, const std::string& name, double mass,
                          const Eigen::Vector3d& com_offset, const Eigen::Matrix3d& inertia)
{
  const std::size_t i = indexOf(bodies, name);
  EXPECT_LE(std::abs(bodies.masses[i] - mass), kRelativeTolerance * mass)
      << name << ": mass " << bodies.masses[i] << " kg, expected " << mass;
  const Eigen::Vector3d& com = bodies.com_offsets.at(i);
  EXPECT_LE((com - com_offset).norm(), kLengthTolerance)
      << name << ": COM offset " << com.transpose() << ", expected " << com_offset.transpose();
  const Eigen::Matrix3d& served = bodies.inertias.at(i);
  EXPECT_LE(maxAbs(served - inertia), kRelativeTolerance * maxAbs(inertia))
      << name << ": inertia\n" << served << "\nexpected\n" << inertia;
}

/// The body-frame vertices of `name` in order: at q = 0 (R = I, t = 0) the
/// served positions p = R p0 + t are p0.
void expectVertices(const std::string& name, const std::vector<Eigen::Vector3d>& p0)
{
  const Eigen::Matrix3Xd positions = server().vertexJacobians(name, Vector6d::Zero()).positions;
  ASSERT_EQ(static_cast<std::size_t>(positions.cols()), p0.size()) << name;
  for (std::size_t v = 0; v < p0.size(); ++v)
    EXPECT_LE((positions.col(v) - p0[v]).norm(), kLengthTolerance)
        << name << " vertex " << v << ": " << positions.col(v).transpose() << ", expected " << p0[v].transpose();
}

/// Child frames of every TFMessage received on a topic.
class FrameRecorder
{
public:
  explicit FrameRecorder(const std::string& topic)
  {
    subscriber_ = ros::NodeHandle().subscribe(topic, 100, &FrameRecorder::onMessage, this);
  }
  /// Waits until `count` messages have arrived; false if they did not within kTimeout.
  bool waitForMessages(std::size_t count)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
    while (ros::WallTime::now() < deadline)
    {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (messages_.size() >= count)
          return true;
      }
      ros::WallDuration(0.01).sleep();
    }
    return false;
  }
  /// Child frames of each message so far.
  std::vector<std::set<std::string>> messages()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }

private:
  void onMessage(const tf2_msgs::TFMessage::ConstPtr& message)
  {
    std::set<std::string> frames;
    for (const geometry_msgs::TransformStamped& transform : message->transforms)
      frames.insert(transform.child_frame_id);
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back(frames);
  }
  std::mutex mutex_;
  std::vector<std::set<std::string>> messages_;
  ros::Subscriber subscriber_;
};

/// The bodies that bodies_subset.test selects with ~bodies.
const std::set<std::string> kSelected = { "tet", "roller" };

/// [kg/m^3] ~density in density.test.
constexpr double kDensity = 2700.0;

std::string joined(const std::set<std::string>& names)
{
  std::string text;
  for (const std::string& name : names)
    text += (text.empty() ? "" : ", ") + name;
  return "{" + text + "}";
}
}  // namespace

// ---------------------------------------------------------------------------
// ~bodies: [roller, tet] (bodies_subset.test). brick (with its merged links
// brick_cap and brick_tip) is not modelled.

TEST(BodiesSubset, OnlyTheSelectedBodiesAreServed)
{
  const FixtureScene fixture = fixtureScene();
  const diff_rigid_body_ros::Bodies bodies = server().bodies();
  EXPECT_EQ(std::set<std::string>(bodies.names.begin(), bodies.names.end()), kSelected);
  ASSERT_EQ(bodies.names.size(), kSelected.size());
  ASSERT_EQ(bodies.masses.size(), kSelected.size());
  ASSERT_EQ(bodies.com_offsets.size(), kSelected.size());
  ASSERT_EQ(bodies.inertias.size(), kSelected.size());
  ASSERT_EQ(bodies.vertex_counts.size(), kSelected.size());
  // The selected bodies are exactly as in the full scene.
  for (const std::string& name : kSelected)
  {
    const FixtureBody& body = fixture.body(name);
    expectMassProperties(bodies, name, body.mass, body.com_offset, body.inertia_body);
    EXPECT_EQ(bodies.vertex_counts[indexOf(bodies, name)], body.expected_vertex_count) << name;
    expectVertices(name, body.p0);
  }

  // Initial states from the URDF: R(q) = the link's rotation, t = its COM.
  std::set<std::string> stated;
  for (const auto& [name, q] : server().getState())
  {
    stated.insert(name);
    if (!kSelected.count(name))
      continue;
    const FixtureBody& body = fixture.body(name);
    EXPECT_LE(maxAbs(refRotation(q[0], q[1], q[2]) - body.initial_link_pose.linear()), kRelativeTolerance) << name;
    EXPECT_LE((q.tail<3>() - body.initial_link_pose * body.com_offset).norm(), kLengthTolerance) << name;
  }
  EXPECT_EQ(stated, kSelected);

  // brick is unknown to every service.
  DRB_EXPECT_THROWS_MESSAGE(server().getState({ "brick" }), ServiceError, "unknown body 'brick'");
  DRB_EXPECT_THROWS_MESSAGE(server().vertexJacobians("brick"), ServiceError, "unknown body 'brick'");
  DRB_EXPECT_THROWS_MESSAGE(server().massMatrices({ "brick" }, {}, false), ServiceError, "unknown body 'brick'");
  DRB_EXPECT_THROWS_MESSAGE(server().setState("brick", Vector6d::Zero()), ServiceError, "unknown body 'brick'");
}

TEST(BodiesSubset, TfPublishesOnlyTheSelectedBodies)
{
  FrameRecorder tf("/tf"), tf_static("/tf_static");
  // Every publication carries all body frames in one message; a few of them.
  ASSERT_TRUE(tf.waitForMessages(5)) << "fewer than 5 messages on /tf within " << kTimeout << " s";
  ASSERT_TRUE(tf_static.waitForMessages(1)) << "no message on /tf_static within " << kTimeout << " s";
  for (const std::set<std::string>& frames : tf.messages())
    EXPECT_EQ(frames, kSelected) << "a /tf message with frames " << joined(frames);
  // Static links stay static; no frame of the unmodelled body appears.
  std::set<std::string> static_frames;
  for (const std::set<std::string>& frames : tf_static.messages())
    static_frames.insert(frames.begin(), frames.end());
  std::set<std::string> expected_static;
  for (const FixtureStaticLink& link : fixtureScene().static_links)
    expected_static.insert(link.name);
  EXPECT_EQ(static_frames, expected_static) << "/tf_static frames " << joined(static_frames);
}

// ---------------------------------------------------------------------------
// ~geometry:=visual (geometry_visual.test).

TEST(VisualGeometry, VerticesComeFromVisualGeometry)
{
  // The fixture with brick's own vertices from its <visual> sphere (r = 3 m,
  // no origin) instead of its two <collision> boxes. brick_tip and brick_cap
  // have no <visual>, so their <collision> geometry is used; brick_cap's
  // corners no longer meet brick's, so all 8 count. tet has no <visual>
  // (collision used); roller has only a <visual> (used either way). Mass
  // properties come from <inertial> and do not change.
  FixtureScene fixture = fixtureScene();
  for (FixtureBody& body : fixture.bodies)
    if (body.name == "brick")
    {
      body.links[0].vertices = sphereVertices(3.0);
      body.expected_vertex_count = 114 + 4 + 8;
      body.finish();
    }

  const diff_rigid_body_ros::Bodies bodies = server().bodies();
  ASSERT_EQ(bodies.names.size(), fixture.bodies.size());
  for (std::size_t i = 0; i < fixture.bodies.size(); ++i)
  {
    const FixtureBody& body = fixture.bodies[i];
    EXPECT_EQ(bodies.names[i], body.name);
    ASSERT_EQ(body.p0.size(), body.expected_vertex_count) << "fixture transcription of " << body.name;
    EXPECT_EQ(bodies.vertex_counts[i], body.expected_vertex_count) << body.name;
    expectMassProperties(bodies, body.name, body.mass, body.com_offset, body.inertia_body);
    expectVertices(body.name, body.p0);
  }

  // At a generic q, p = R p0 + t with the visual vertices.
  const FixtureBody& brick = fixture.body("brick");
  Vector6d q;
  q << 0.7, -0.3, 2.1, 0.4, -1.2, 0.9;
  const Eigen::Matrix3Xd positions = server().vertexJacobians("brick", q).positions;
  ASSERT_EQ(static_cast<std::size_t>(positions.cols()), brick.p0.size());
  for (std::size_t v = 0; v < brick.p0.size(); ++v)
    EXPECT_LE((positions.col(v) - refPosition(q, brick.p0[v])).norm(), kLengthTolerance) << "brick vertex " << v;
}

// ---------------------------------------------------------------------------
// ~density = 2700 kg/m^3 (density.test, test/urdf/density_scene.urdf). Solid
// bodies of uniform density, about their COM:
//   box a x b x c:        m = rho a b c,          I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2)
//   cylinder r, l (on z): m = rho pi r^2 l,       I = diag(m (3 r^2 + l^2)/12, same, m r^2/2)
//   sphere r:             m = rho 4/3 pi r^3,     I = 2/5 m r^2 I3
//   right tetrahedron with legs a, b, c on x, y, z from the origin:
//                         m = rho a b c / 6,      COM = (a, b, c)/4,
//                         Ixx = 3 m (b^2 + c^2)/80 (and cyclically),
//                         Ixy = m a b/80, Ixz = m a c/80, Iyz = m b c/80
//     (from integral x^2 dV = V a^2/10 and integral x y dV = V a b/20 over it).
// A geometry <origin> (xyz, R_o) moves the COM to xyz and turns I into R_o I R_o^T.

TEST(Density, MassPropertiesFromClosedGeometry)
{
  const diff_rigid_body_ros::Bodies bodies = server().bodies();
  EXPECT_EQ(bodies.names, (std::vector<std::string>{ "slab", "puck", "ball", "wedge", "anchor" }));

  {  // slab: box 0.4 x 0.2 x 0.1 at origin xyz (0.05, -0.02, 0.03), rpy (0.3, -0.2, 0.5)
    const double a = 0.4, b = 0.2, c = 0.1;
    const double m = kDensity * a * b * c;
    const Eigen::Matrix3d I_box =
        m / 12 * Eigen::Vector3d(b * b + c * c, a * a + c * c, a * a + b * b).asDiagonal().toDenseMatrix();
    const Eigen::Matrix3d R_o = refRotation(0.3, -0.2, 0.5);
    const Eigen::Vector3d xyz(0.05, -0.02, 0.03);
    expectMassProperties(bodies, "slab", m, xyz, R_o * I_box * R_o.transpose());
    // Body frame at the COM: p0 = R_o corner + xyz - COM = R_o corner.
    expectVertices("slab", transformed(urdfPose(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.3, -0.2, 0.5)),
                                       boxCorners(Eigen::Vector3d(a, b, c))));
  }
  {  // puck: cylinder r = 0.1, l = 0.05
    const double r = 0.1, l = 0.05;
    const double m = kDensity * kPi * r * r * l;
    const double side = m * (3 * r * r + l * l) / 12;
    expectMassProperties(bodies, "puck", m, Eigen::Vector3d::Zero(),
                         Eigen::Vector3d(side, side, m * r * r / 2).asDiagonal().toDenseMatrix());
  }
  {  // ball: sphere r = 0.05
    const double r = 0.05;
    const double m = kDensity * 4.0 / 3.0 * kPi * r * r * r;
    expectMassProperties(bodies, "ball", m, Eigen::Vector3d::Zero(), 0.4 * m * r * r * Eigen::Matrix3d::Identity());
  }
  {  // wedge: tetrahedron.obj scaled to legs 0.2, 0.3, 0.4
    const double a = 0.2, b = 0.3, c = 0.4;
    const double m = kDensity * a * b * c / 6;
    Eigen::Matrix3d I;
    I << 3 * m * (b * b + c * c) / 80, m * a * b / 80, m * a * c / 80,  //
        m * a * b / 80, 3 * m * (a * a + c * c) / 80, m * b * c / 80,   //
        m * a * c / 80, m * b * c / 80, 3 * m * (a * a + b * b) / 80;
    const Eigen::Vector3d com = Eigen::Vector3d(a, b, c) / 4;
    expectMassProperties(bodies, "wedge", m, com, I);
    expectVertices("wedge", transformed(urdfPose(-com), tetrahedronObj(Eigen::Vector3d(a, b, c))));
  }
  // anchor: its <inertial>, not its box at kDensity (which would be 72.9 kg).
  expectMassProperties(bodies, "anchor", 1.25, Eigen::Vector3d::Zero(),
                       Eigen::Vector3d(0.01, 0.02, 0.03).asDiagonal().toDenseMatrix());

  // Tessellations: box 8, cylinder 2 x 32, sphere 114, tetrahedron 4, box 8.
  EXPECT_EQ(bodies.vertex_counts, (std::vector<std::uint32_t>{ 8, 64, 114, 4, 8 }));
}

}  // namespace drb_rostest
