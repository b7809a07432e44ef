// SceneOptions::floating_base (~floating_base) against the hand-written
// alternative: the same URDF text with `<link name="world"/>` and a floating
// joint from it to the root link inserted by this test, loaded without the
// option. Every answer (the model, M and dM/dx, vertex Jacobians, backprop,
// inverse and forward dynamics with derivatives, link poses) must match bit
// for bit; the gravity term of the robot held still is its total weight along
// tz, with the masses summed from the URDF text here.
#include <cstring>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../support/articulated_fixtures.h"
#include "../support/expect_throws.h"
#include "../support/oracles.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using drb_test::articulated::kErd;
using drb_test::articulated::readText;
using drb_test::articulated::robotOptions;

namespace
{
constexpr double kGravity = 9.81;              // m/s^2, standardGravity()
constexpr double kRelativeTolerance = 1e-13;   // of the total weight
constexpr int kConfigurations = 3;

struct Robot
{
  const char* name;
  std::string path;
  const char* root;      ///< the URDF's root link, read off the file by hand
  std::size_t joints;    ///< its independent 1-dof joints (mimic joints left out), counted by hand
  const char* frame;     ///< the fixed frame above the root ("" = the default, world)
};

std::vector<Robot> robots()
{
  return { { "simple_humanoid", kErd + "/simple_humanoid_description/urdf/simple_humanoid.urdf", "base_link", 29,
             "" },
           { "panda", kErd + "/panda_description/urdf/panda.urdf", "panda_link0", 8, "" },
           { "double_pendulum", kErd + "/double_pendulum_description/urdf/double_pendulum.urdf", "base_link", 2,
             "" },
           // Its root is a link 'world' (fixed to base_link): the new frame needs another name.
           { "ur5", kErd + "/ur_description/urdf/ur5_robot.urdf", "world", 6, "odom" } };
}

/// `urdf` with `<link name="frame"/>` and a floating joint from it to `root` right after the <robot ...> tag.
std::string handWrittenWrapper(const std::string& urdf, const std::string& root, const std::string& frame)
{
  const std::size_t tag_end = urdf.find('>', urdf.find("<robot"));
  return urdf.substr(0, tag_end + 1) + "<link name=\"" + frame + "\"/><joint name=\"floating_base\" type=\"floating\">" +
         "<parent link=\"" + frame + "\"/><child link=\"" + root + "\"/></joint>" + urdf.substr(tag_end + 1);
}

/// The sum of every <mass value="..."/> of the URDF text [kg].
double totalMass(const std::string& urdf)
{
  const std::regex mass("<mass\\s+value=\"([^\"]+)\"");
  double total = 0.0;
  for (auto m = std::sregex_iterator(urdf.begin(), urdf.end(), mass); m != std::sregex_iterator(); ++m)
    total += std::stod((*m)[1]);
  return total;
}

void expectSameBits(const std::vector<double>& a, const std::vector<double>& b, const std::string& what)
{
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0) << what << ": not bit for bit";
}

std::vector<double> flat(const Eigen::MatrixXd& m)
{
  return std::vector<double>(m.data(), m.data() + m.size());
}

struct Loaded
{
  drb::SceneQueries option;   ///< floating_base: true
  drb::SceneQueries wrapper;  ///< the hand-written wrapper
};

Loaded load(const Robot& robot)
{
  drb::SceneOptions options = robotOptions(drb::JointHandling::Model);
  options.base_directory = robot.path.substr(0, robot.path.find_last_of('/'));
  drb::SceneOptions floating = options;
  floating.floating_base = true;
  floating.fixed_frame = robot.frame;
  const std::string text = readText(robot.path);
  const std::string frame = *robot.frame ? robot.frame : "world";
  return { drb::SceneQueries(drb::loadSceneFromUrdf(text, floating)),
           drb::SceneQueries(drb::loadSceneFromUrdf(handWrittenWrapper(text, robot.root, frame), options)) };
}

/// Random x: angles in (-pi, pi), the COM in [-1, 1]^3 m, joints in [-1.5, 1.5].
std::vector<double> randomConfigurations(std::size_t dofs, drb_test::Random& rng)
{
  std::vector<double> q(dofs * kConfigurations);
  for (std::size_t i = 0; i < q.size(); ++i)
  {
    const std::size_t k = i % dofs;
    q[i] = k < 3 ? rng.uniform(-3.1, 3.1) : k < 6 ? rng.uniform(-1.0, 1.0) : rng.uniform(-1.5, 1.5);
  }
  return q;
}
}  // namespace

TEST(FloatingBase, TheRootLinkIsOneFreeRootedBodyInANewFixedFrame)
{
  for (const Robot& robot : robots())
  {
    SCOPED_TRACE(robot.name);
    const Loaded loaded = load(robot);
    const drb::Scene& scene = loaded.option.scene();
    EXPECT_EQ(scene.fixed_frame, *robot.frame ? robot.frame : "world");
    ASSERT_EQ(scene.bodies.size(), 1u);
    EXPECT_EQ(scene.bodies[0].name, robot.root);
    EXPECT_EQ(scene.bodies[0].coordinates, 6 + robot.joints);
    EXPECT_TRUE(scene.bodies[0].hasFreeRoot());
    EXPECT_TRUE(scene.static_links.empty());
  }
}

TEST(FloatingBase, AnswersEqualTheHandWrittenWrapperBitForBit)
{
  drb_test::Random rng(27);
  for (const Robot& robot : robots())
  {
    SCOPED_TRACE(robot.name);
    const Loaded loaded = load(robot);
    const drb::BodyModel& a = loaded.option.body(0);
    const drb::BodyModel& b = loaded.wrapper.body(0);
    ASSERT_EQ(loaded.wrapper.bodyCount(), 1u);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.joint_names, b.joint_names);
    EXPECT_EQ(loaded.option.scene().fixed_frame, loaded.wrapper.scene().fixed_frame);
    expectSameBits(flat(a.vertices), flat(b.vertices), "vertices");
    expectSameBits(flat(a.initial_x), flat(b.initial_x), "initial x");

    const drb::SceneState state_a = loaded.option.initialState(), state_b = loaded.wrapper.initialState();
    const std::vector<double> q = randomConfigurations(a.coordinates, rng);
    std::vector<double> qdot(q.size()), qddot(q.size()), gradients(3 * a.vertexCount() * kConfigurations);
    for (double& v : qdot)
      v = rng.uniform(-2.0, 2.0);
    for (double& v : qddot)
      v = rng.uniform(-3.0, 3.0);
    for (double& g : gradients)
      g = rng.uniform(-1.0, 1.0);
    const std::vector<std::string> names{ a.name };

    const drb::MassMatrixAnswer m_a = loaded.option.massMatrices(state_a, names, q, true);
    const drb::MassMatrixAnswer m_b = loaded.wrapper.massMatrices(state_b, names, q, true);
    expectSameBits(m_a.mass_matrices, m_b.mass_matrices, "M");
    expectSameBits(m_a.derivatives, m_b.derivatives, "dM/dx");

    std::vector<double> p_a, J_a, p_b, J_b;
    loaded.option.vertexJacobians(state_a, a.name, {}, q, p_a, J_a);
    loaded.wrapper.vertexJacobians(state_b, b.name, {}, q, p_b, J_b);
    expectSameBits(p_a, p_b, "positions");
    expectSameBits(J_a, J_b, "vertex Jacobians");
    expectSameBits(loaded.option.backpropConfigurations(state_a, a.name, {}, gradients, q),
                   loaded.wrapper.backpropConfigurations(state_b, b.name, {}, gradients, q), "backprop");

    drb::InverseDynamicsAnswer id_a, id_b;
    loaded.option.inverseDynamics(state_a, names, q, qdot, qddot, true, true, id_a);
    loaded.wrapper.inverseDynamics(state_b, names, q, qdot, qddot, true, true, id_b);
    for (const auto& field : { &drb::InverseDynamicsAnswer::tau, &drb::InverseDynamicsAnswer::coriolis_matrices,
                               &drb::InverseDynamicsAnswer::dtau_dq, &drb::InverseDynamicsAnswer::dtau_dqdot })
      expectSameBits(id_a.*field, id_b.*field, "inverse dynamics");
    drb::ForwardDynamicsAnswer fd_a, fd_b;
    loaded.option.forwardDynamics(state_a, names, q, qdot, id_a.tau, true, fd_a);
    loaded.wrapper.forwardDynamics(state_b, names, q, qdot, id_a.tau, true, fd_b);
    for (const auto& field : { &drb::ForwardDynamicsAnswer::qddot, &drb::ForwardDynamicsAnswer::dqddot_dq,
                               &drb::ForwardDynamicsAnswer::dqddot_dqdot, &drb::ForwardDynamicsAnswer::dqddot_dtau })
      expectSameBits(fd_a.*field, fd_b.*field, "forward dynamics");

    std::vector<Eigen::Isometry3d> poses_a, poses_b;
    const Eigen::Map<const Eigen::VectorXd> x(q.data(), static_cast<Eigen::Index>(a.coordinates));
    loaded.option.linkPoses(0, x, poses_a);
    loaded.wrapper.linkPoses(0, x, poses_b);
    ASSERT_EQ(poses_a.size(), poses_b.size());
    for (std::size_t l = 0; l < poses_a.size(); ++l)
      expectSameBits(flat(poses_a[l].matrix()), flat(poses_b[l].matrix()), "link pose " + std::to_string(l));
  }
}

TEST(FloatingBase, HoldingTheRobotStillTakesItsTotalWeightAlongTz)
{
  drb_test::Random rng(2027);
  for (const Robot& robot : robots())
  {
    SCOPED_TRACE(robot.name);
    const Loaded loaded = load(robot);
    const double weight = totalMass(readText(robot.path)) * kGravity;  // N
    const std::size_t d = loaded.option.dofs(0);
    const std::vector<double> q = randomConfigurations(d, rng);
    drb::InverseDynamicsAnswer answer;
    loaded.option.inverseDynamics(loaded.option.initialState(), {}, q, {}, {}, false, false, answer);
    for (int k = 0; k < kConfigurations; ++k)
    {
      const double* g = answer.gravity_terms.data() + k * d;
      EXPECT_NEAR(g[3], 0.0, kRelativeTolerance * weight) << "configuration " << k << ": f_x";
      EXPECT_NEAR(g[4], 0.0, kRelativeTolerance * weight) << "configuration " << k << ": f_y";
      EXPECT_NEAR(g[5], weight, kRelativeTolerance * weight) << "configuration " << k << ": f_z";
    }
  }
}

TEST(FloatingBase, AFixedFrameThatIsALinkIsRefused)
{
  const Robot ur5 = robots().back();
  drb::SceneOptions options = robotOptions(drb::JointHandling::Model);
  options.floating_base = true;
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdfFile(ur5.path, options), drb::SceneDescriptionError,
                            "parameter fixed_frame: 'world' is a link of the URDF (its root); with floating_base the "
                            "fixed frame is a new frame above the root link 'world'");
  options.fixed_frame = "tool0";
  DRB_EXPECT_THROWS_MESSAGE(drb::loadSceneFromUrdfFile(ur5.path, options), drb::SceneDescriptionError,
                            "parameter fixed_frame: 'tool0' is a link of the URDF; with floating_base");
}

TEST(FloatingBase, AJointNamedFloatingBaseKeepsItsName)
{
  using namespace drb_test::urdf;
  // A fixed-base pendulum whose one joint is called floating_base: the added joint takes another name.
  const std::string xml = robot(link("arm", inertial()) + "<joint name=\"floating_base\" type=\"revolute\">"
                                "<parent link=\"world\"/><child link=\"arm\"/><axis xyz=\"0 0 1\"/>"
                                "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>");
  drb::SceneOptions options;
  options.floating_base = true;
  options.fixed_frame = "odom";
  const drb::Scene scene = drb::loadSceneFromUrdf(xml, options);
  ASSERT_EQ(scene.bodies.size(), 1u);
  EXPECT_EQ(scene.bodies[0].name, "world");
  EXPECT_EQ(scene.bodies[0].coordinates, 7u);
  EXPECT_EQ(scene.bodies[0].joint_names, std::vector<std::string>{ "floating_base" });
}
