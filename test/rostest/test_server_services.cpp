// The services (get_bodies ... backprop) of a running rigid_body_server on the fixture scene
// (test/urdf/fixture_scene.urdf), checked against
//   (a) central finite differences of the positions and mass matrices the
//       service itself returns at perturbed q (independent of its Jacobian
//       and derivative code);
//   (b) docs/derivation.md evaluated in the test (test/support/kinematics_oracles.h:
//       products of elementary rotations, M = blockdiag(T^T R I_b R^T T, m I3),
//       J = [-[R p0]_x T, I3]; fixture_scene.h: composite inertia by the
//       parallel-axis theorem);
//   (c) the core library loading the same URDF in this process.
// The node is reached through the shipped C++ client (RigidBodyClient).
//
// Runs in services.test (fresh node). Every test leaves the node's state as
// it found it (RestoresState), so the tests run in any order.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <ros/package.h>

#include "diff_rigid_body/parsers/urdf_scene.h"
#include "server_under_test.h"

namespace drb_rostest
{
namespace
{
/// Relative tolerance for M, J, positions, masses and inertias against the
/// independent oracle, relative to the largest entry (or |t| + |p0| for
/// positions). Both sides round differently (A^T I_b A against
/// T^T R I_b R^T T), so this is a few hundred ulp of headroom.
constexpr double kRelativeTolerance = 1e-12;  // 1
/// COM offsets and vertices of the fixture (sizes ~1 m).
constexpr double kLengthTolerance = 1e-12;  // m
/// Central-difference step in every coordinate.
constexpr double kFiniteDifferenceStep = 1e-6;  // rad or m
/// Central differences: truncation h^2/6 |f'''| ~ 1e-13 plus rounding
/// eps |f| / h ~ 2e-10, relative to max(1, largest entry).
constexpr double kFiniteDifferenceTolerance = 1e-8;  // 1

/// Tracks the largest error of a kind and records it in the test's XML
/// result and on stdout (the numbers quoted in reports come from here).
class MaxError
{
public:
  explicit MaxError(std::string what) : what_(std::move(what)) {}
  ~MaxError()
  {
    ::testing::Test::RecordProperty(what_, std::to_string(max_));
    std::printf("[ measured ] %-48s max error %.3e\n", what_.c_str(), max_);
  }
  double operator()(double error)
  {
    max_ = std::max(max_, error);
    return error;
  }

private:
  std::string what_;
  double max_ = 0.0;
};

double maxAbs(const Eigen::MatrixXd& m)
{
  return m.size() ? m.cwiseAbs().maxCoeff() : 0.0;
}

/// Fixed-seed test states: generic ones, angles far outside (-pi, pi], and
/// one near (not at) gimbal lock.
std::vector<Vector6d> testStates(unsigned seed)
{
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> angle(-kPi, kPi), tilt(-1.4, 1.4), position(-2.0, 2.0);
  std::vector<Vector6d> states;
  for (int k = 0; k < 3; ++k)
  {
    Vector6d q;
    q << angle(random), tilt(random), angle(random), position(random), position(random), position(random);
    states.push_back(q);
  }
  Vector6d wound;
  wound << 1000.3, -7.1, 123.4, 0.5, -0.25, 3.0;
  states.push_back(wound);
  Vector6d near_lock;
  near_lock << 0.7, kPi / 2 - 1e-3, -2.2, -1.0, 0.0, 0.5;
  states.push_back(near_lock);
  return states;
}

const FixtureScene& fixture()
{
  static const FixtureScene scene = fixtureScene();
  return scene;
}

/// Every test of these suites restores the node's state when it ends.
class Services : public RestoresState
{
};
class GimbalLock : public RestoresState
{
};

/// Central differences of the service's positions of `body` at q: column j
/// of vertex v's block is (p_v(q + h e_j) - p_v(q - h e_j)) / (2 h).
std::vector<Matrix36d> positionDifferences(const std::string& body, const Vector6d& q)
{
  std::vector<Matrix36d> fd;
  for (int j = 0; j < 6; ++j)
  {
    Vector6d qp = q, qm = q;
    qp[j] += kFiniteDifferenceStep;
    qm[j] -= kFiniteDifferenceStep;
    const Eigen::Matrix3Xd difference =
        (server().vertexJacobians(body, qp).positions - server().vertexJacobians(body, qm).positions) /
        (2 * kFiniteDifferenceStep);
    fd.resize(difference.cols());
    for (Eigen::Index v = 0; v < difference.cols(); ++v)
      fd[v].col(j) = difference.col(v);
  }
  return fd;
}

std::string fixtureUrdfPath()
{
  std::string path;
  if (!ros::NodeHandle("~").getParam("urdf_path", path))
    throw std::runtime_error("test node parameter ~urdf_path is not set");
  return path;
}
}  // namespace

// ---------------------------------------------------------------------------

TEST_F(Services, InitialStateFromUrdfJointOrigins)
{
  const NamedStates state = server().getState();
  ASSERT_EQ(state.size(), fixture().bodies.size());
  MaxError rotation_error("initial state: R(q) vs joint origins"), com_error("initial state: t vs joint origins [m]");
  for (std::size_t i = 0; i < fixture().bodies.size(); ++i)
  {
    const FixtureBody& body = fixture().bodies[i];
    EXPECT_EQ(state[i].first, body.name);
    const Vector6d& q = state[i].second;
    const Eigen::Matrix3d R = refRotation(q[0], q[1], q[2]);
    EXPECT_LE(rotation_error(maxAbs(R - body.initial_link_pose.linear())), kRelativeTolerance) << body.name;
    // t is the COM, not the link origin.
    EXPECT_LE(com_error((q.tail<3>() - body.initial_link_pose * body.com_offset).norm()), kLengthTolerance)
        << body.name;
  }
}

TEST_F(Services, GetBodiesAgainstIndependentMassProperties)
{
  const diff_rigid_body_ros::Bodies bodies = server().bodies();
  EXPECT_EQ(bodies.fixed_frame, fixture().fixed_frame);
  const std::size_t n = fixture().bodies.size();
  ASSERT_EQ(bodies.names.size(), n);
  ASSERT_EQ(bodies.masses.size(), n);
  ASSERT_EQ(bodies.inertias.size(), n);
  ASSERT_EQ(bodies.com_offsets.size(), n);
  ASSERT_EQ(bodies.vertex_counts.size(), n);
  MaxError mass_error("get_bodies: mass vs parallel-axis oracle (rel)"),
      inertia_error("get_bodies: inertia vs parallel-axis oracle (rel)"),
      com_error("get_bodies: com_offset vs oracle [m]");
  for (std::size_t i = 0; i < n; ++i)
  {
    const FixtureBody& body = fixture().bodies[i];
    EXPECT_EQ(bodies.names[i], body.name);
    EXPECT_EQ(bodies.vertex_counts[i], body.expected_vertex_count) << body.name;
    EXPECT_EQ(body.p0.size(), body.expected_vertex_count) << "fixture transcription of " << body.name;
    EXPECT_LE(mass_error(std::abs(bodies.masses[i] - body.mass) / body.mass), kRelativeTolerance) << body.name;
    const Eigen::Matrix3d& inertia = bodies.inertias[i];
    EXPECT_LE(inertia_error(maxAbs(inertia - body.inertia_body) / maxAbs(body.inertia_body)), kRelativeTolerance)
        << body.name << ":\n" << inertia << "\nexpected\n" << body.inertia_body;
    EXPECT_LE(com_error((bodies.com_offsets[i] - body.com_offset).norm()), kLengthTolerance) << body.name;
  }
}

TEST_F(Services, AgreesWithCoreLibraryOnTheSameUrdf)
{
  diff_rigid_body::SceneOptions options;
  options.joints = diff_rigid_body::JointHandling::Free;  // as services.test runs the node (~joints: free)
  options.find_package = [](const std::string& package) { return ros::package::getPath(package); };
  const diff_rigid_body::Scene scene = diff_rigid_body::loadSceneFromUrdfFile(fixtureUrdfPath(), options);
  const diff_rigid_body_ros::Bodies bodies = server().bodies();
  ASSERT_EQ(bodies.names.size(), scene.bodies.size());
  MaxError order_error("vertices in body frame vs fixture order [m]");
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
  {
    const diff_rigid_body::BodyModel& core = scene.bodies[i];
    // The node copies these through; they must be bit for bit the same.
    EXPECT_EQ(bodies.names[i], core.name);
    EXPECT_EQ(bodies.masses[i], core.mass());
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(bodies.com_offsets[i][k], core.rootComOffset()[k]);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(bodies.inertias[i](r, c), core.segments[0].inertia.inertia(r, c));
    ASSERT_EQ(bodies.vertex_counts[i], static_cast<std::uint32_t>(core.vertices.cols()));

    // At q = 0, p = p0: the service's positions are the core's body-frame
    // vertices exactly, and those are the fixture's, in the documented order.
    const diff_rigid_body_ros::VertexJacobians at_zero = server().vertexJacobians(core.name, Vector6d::Zero());
    ASSERT_EQ(at_zero.positions.cols(), core.vertices.cols());
    const FixtureBody& body = fixture().body(core.name);
    ASSERT_EQ(body.p0.size(), static_cast<std::size_t>(core.vertices.cols()));
    for (Eigen::Index v = 0; v < core.vertices.cols(); ++v)
    {
      EXPECT_TRUE(at_zero.positions.col(v) == core.vertices.col(v))
          << core.name << " vertex " << v << ": " << at_zero.positions.col(v).transpose() << " vs core "
          << core.vertices.col(v).transpose();
      EXPECT_LE(order_error((core.vertices.col(v) - body.p0[v]).norm()), kLengthTolerance)
          << core.name << " vertex " << v << ": " << core.vertices.col(v).transpose() << ", fixture expects "
          << body.p0[v].transpose();
    }
  }
}

TEST_F(Services, SetStateIsStoredBitForBit)
{
  const NamedStates before = server().getState();
  // Angles far outside (-pi, pi], -0, a subnormal: stored as given, no wrapping.
  Vector6d brick, tet;
  brick << 1.0e6, -7.5, 3 * kPi, -0.0, 4.9e-324, 1e-300;
  tet << -12.25, kPi / 2, -kPi, 1e5, -2.0, 0.125;
  const NamedStates update = { { "tet", tet }, { "brick", brick } };
  server().setState(update);

  const NamedStates subset = server().getState({ "tet", "brick" });
  EXPECT_TRUE(bitwiseEqual(subset, update)) << describe(subset);

  // Bodies left out of the request keep their state.
  const NamedStates all = server().getState();
  ASSERT_EQ(all.size(), 3u);
  ASSERT_EQ(before.size(), 3u);
  EXPECT_TRUE(bitwiseEqual({ all[2] }, { before[2] })) << describe(all);
}

TEST_F(Services, MassMatricesAgainstOracleAndFiniteDifferences)
{
  const std::vector<Vector6d> states = testStates(11);
  const std::size_t n = fixture().bodies.size(), K = states.size();
  // Configuration k: body i gets states[(k + i) % K], so each body sees every state.
  auto state_of = [&](std::size_t k, std::size_t i) { return states[(k + i) % K]; };
  std::vector<double> q;
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t i = 0; i < n; ++i)
      for (int j = 0; j < 6; ++j)
        q.push_back(state_of(k, i)[j]);
  const diff_rigid_body_ros::MassMatrices answer = server().massMatrices({}, q, true);
  ASSERT_EQ(answer.bodies.size(), n);
  ASSERT_EQ(answer.M.size(), K * n);
  ASSERT_EQ(answer.dM.size(), K * n);
  ASSERT_EQ(answer.cos_theta.size(), K * n);

  // Finite differences from the service itself: one batched request with
  // configurations (k, j, +/-).
  std::vector<double> q_fd;
  for (std::size_t k = 0; k < K; ++k)
    for (int j = 0; j < 6; ++j)
      for (double sign : { 1.0, -1.0 })
        for (std::size_t i = 0; i < n; ++i)
        {
          Vector6d qi = state_of(k, i);
          qi[j] += sign * kFiniteDifferenceStep;
          for (int c = 0; c < 6; ++c)
            q_fd.push_back(qi[c]);
        }
  const diff_rigid_body_ros::MassMatrices perturbed = server().massMatrices({}, q_fd, false);
  ASSERT_EQ(perturbed.M.size(), 12 * K * n);

  MaxError m_error("M vs oracle T^T R I_b R^T T (rel)"), dm_error("dM/dq vs central differences of M (rel)"),
      cos_error("cos_theta vs cos(theta)");
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t i = 0; i < n; ++i)
    {
      const FixtureBody& body = fixture().bodies[i];
      EXPECT_EQ(answer.bodies[i], body.name);
      const std::size_t slot = k * n + i;
      const Vector6d qi = state_of(k, i);
      const Matrix6d& M = answer.M[slot];
      const Matrix6d expected = refMassMatrix(qi, body.mass, body.inertia_body);
      EXPECT_LE(m_error(maxAbs(M - expected) / maxAbs(expected)), kRelativeTolerance)
          << body.name << " at q = " << qi.transpose() << "\n" << M << "\nexpected\n" << expected;
      EXPECT_LE(maxAbs(M - M.transpose()), kRelativeTolerance * maxAbs(M)) << "M not symmetric:\n" << M;
      EXPECT_LE(cos_error(std::abs(answer.cos_theta[slot] - std::cos(qi[1]))), 1e-15);
      const double scale = std::max(1.0, maxAbs(M));
      for (int j = 0; j < 6; ++j)
      {
        const Matrix6d& dM = answer.dM[slot][j];
        const Matrix6d& plus = perturbed.M[((k * 6 + j) * 2 + 0) * n + i];
        const Matrix6d& minus = perturbed.M[((k * 6 + j) * 2 + 1) * n + i];
        const Matrix6d fd = (plus - minus) / (2 * kFiniteDifferenceStep);
        EXPECT_LE(dm_error(maxAbs(dM - fd) / scale), kFiniteDifferenceTolerance)
            << body.name << " dM/dq_" << j << " at q = " << qi.transpose() << "\n" << dM << "\nfd\n" << fd;
        if (j >= 2)  // yaw symmetry and translation invariance (docs/derivation.md, "Mass matrix"): exactly zero
        {
          EXPECT_EQ(maxAbs(dM), 0.0) << body.name << " dM/dq_" << j;
        }
      }
    }

  // Empty q means the current state; bodies come back in the requested order.
  const Vector6d roller_q = states[1], brick_q = states[4];
  server().setState({ { "roller", roller_q }, { "brick", brick_q } });
  const diff_rigid_body_ros::MassMatrices current = server().massMatrices({ "roller", "brick" }, {}, false);
  ASSERT_EQ(current.bodies, (std::vector<std::string>{ "roller", "brick" }));
  ASSERT_EQ(current.M.size(), 2u);
  ASSERT_THROW(server().massMatrices({ "roller", "brick" }, toStdVector(roller_q), false), ServiceError)
      << "6 values for 2 bodies must be refused";
  std::vector<double> both = toStdVector(roller_q);
  both.insert(both.end(), brick_q.data(), brick_q.data() + 6);
  const diff_rigid_body_ros::MassMatrices with_q = server().massMatrices({ "roller", "brick" }, both, false);
  EXPECT_TRUE(current.M == with_q.M);
  // The client does not show the derivatives array when none were asked for: a raw call does.
  drb::GetMassMatrix::Request no_derivatives;
  no_derivatives.bodies = { "roller", "brick" };
  EXPECT_TRUE(rawServer().call<drb::GetMassMatrix>("get_mass_matrix", no_derivatives).derivatives.empty());
}

TEST_F(Services, VertexJacobiansAgainstOracleAndFiniteDifferences)
{
  MaxError p_error("positions vs oracle R p0 + t (rel)"), j_error("J vs oracle [-[R p0]x T, I3] (rel)"),
      fd_error("J vs central differences of positions (rel)");
  for (const FixtureBody& body : fixture().bodies)
    for (const Vector6d& q : testStates(23))
    {
      const diff_rigid_body_ros::VertexJacobians answer = server().vertexJacobians(body.name, q);
      const std::size_t count = body.p0.size();
      ASSERT_EQ(static_cast<std::size_t>(answer.positions.cols()), count);
      ASSERT_EQ(static_cast<std::size_t>(answer.J.rows()), 3 * count);

      const std::vector<Matrix36d> fd = positionDifferences(body.name, q);
      ASSERT_EQ(fd.size(), count);
      for (std::size_t v = 0; v < count; ++v)
      {
        const double scale = std::max(1.0, q.tail<3>().norm() + body.p0[v].norm());
        EXPECT_LE(p_error((answer.positions.col(v) - refPosition(q, body.p0[v])).norm() / scale), kRelativeTolerance)
            << body.name << " vertex " << v;
        const Matrix36d J = answer.jacobian(v);
        const Matrix36d expected = refJacobianFromAngularVelocity(q, body.p0[v]);
        EXPECT_LE(j_error(maxAbs(J - expected) / std::max(1.0, maxAbs(expected))), kRelativeTolerance)
            << body.name << " vertex " << v << " at q = " << q.transpose() << "\n" << J << "\nexpected\n" << expected;
        EXPECT_LE(fd_error(maxAbs(J - fd[v]) / scale), kFiniteDifferenceTolerance)
            << body.name << " vertex " << v << " at q = " << q.transpose() << "\n"
            << J << "\nfd\n"
            << fd[v];
      }

      // A selection returns those vertices, in the requested order.
      const std::vector<std::uint32_t> selection{ static_cast<std::uint32_t>(count - 1), 0, 3 };
      const diff_rigid_body_ros::VertexJacobians some = server().vertexJacobians(body.name, q, selection);
      ASSERT_EQ(some.positions.cols(), 3);
      for (std::size_t s = 0; s < selection.size(); ++s)
      {
        EXPECT_TRUE(some.positions.col(s) == answer.positions.col(selection[s]));
        EXPECT_TRUE(some.jacobian(s) == answer.jacobian(selection[s]));
      }
    }

  // Empty q means the current state.
  const Vector6d q = testStates(5)[0];
  server().setState("tet", q);
  const diff_rigid_body_ros::VertexJacobians current = server().vertexJacobians("tet");
  const diff_rigid_body_ros::VertexJacobians explicit_q = server().vertexJacobians("tet", q);
  EXPECT_TRUE(current.positions == explicit_q.positions);
  EXPECT_TRUE(current.J == explicit_q.J);
}

TEST_F(Services, BackpropAgainstJacobianTransposeOracleAndFiniteDifferences)
{
  std::mt19937 random(31);
  std::normal_distribution<double> normal;
  MaxError jt_error("backprop vs sum J^T g of the service's J (rel)"), oracle_error("backprop vs oracle (rel)"),
      fd_error("backprop vs central differences of g.p (rel)");
  for (const FixtureBody& body : fixture().bodies)
    for (const Vector6d& q : testStates(37))
    {
      const std::size_t count = body.p0.size();
      Eigen::Matrix3Xd g(3, count);
      std::vector<Eigen::Vector3d> g3(count);
      for (std::size_t v = 0; v < count; ++v)
        for (int c = 0; c < 3; ++c)
          g(c, v) = g3[v][c] = normal(random);
      const Vector6d gradient = server().backprop(body.name, g, q);

      const diff_rigid_body_ros::VertexJacobians jacobians = server().vertexJacobians(body.name, q);
      Vector6d jt = Vector6d::Zero();
      double magnitude = 0.0;  // sum |J^T| |g|: the scale of the rounding in the sum
      for (std::size_t v = 0; v < count; ++v)
      {
        jt += jacobians.jacobian(v).transpose() * g3[v];
        magnitude += maxAbs(jacobians.jacobian(v)) * g3[v].norm();
      }
      const double scale = std::max(1.0, magnitude);
      EXPECT_LE(jt_error(maxAbs(gradient - jt) / scale), kRelativeTolerance)
          << body.name << ": " << gradient.transpose() << " vs " << jt.transpose();
      EXPECT_LE(oracle_error(maxAbs(gradient - refBackprop(q, body.p0, g3)) / scale), kRelativeTolerance) << body.name;

      // L(q) = sum_i g_i . p_i(q), differentiated through the service's positions.
      for (int j = 0; j < 6; ++j)
      {
        double loss[2];
        for (int s = 0; s < 2; ++s)
        {
          Vector6d qs = q;
          qs[j] += (s == 0 ? 1 : -1) * kFiniteDifferenceStep;
          const diff_rigid_body_ros::VertexJacobians p = server().vertexJacobians(body.name, qs);
          loss[s] = 0.0;
          for (std::size_t v = 0; v < count; ++v)
            loss[s] += g3[v].dot(p.positions.col(v));
        }
        EXPECT_LE(fd_error(std::abs(gradient[j] - (loss[0] - loss[1]) / (2 * kFiniteDifferenceStep)) / scale),
                  kFiniteDifferenceTolerance)
            << body.name << " dL/dq_" << j;
      }

      // A selection: only those vertices' gradients.
      const std::vector<std::uint32_t> selection{ 1, static_cast<std::uint32_t>(count - 1) };
      Eigen::Matrix3Xd g_some(3, 2);
      g_some << g.col(1), g.col(count - 1);
      const Vector6d some = server().backprop(body.name, g_some, q, selection);
      const Vector6d expected_some =
          jacobians.jacobian(1).transpose() * g3[1] + jacobians.jacobian(count - 1).transpose() * g3[count - 1];
      EXPECT_LE(jt_error(maxAbs(some - expected_some) / scale), kRelativeTolerance);
    }
}

// ---------------------------------------------------------------------------
// Gimbal lock: theta = pi/2 - 1e-9 and exactly the double nearest pi/2 (and
// its negative). Everything stays finite, cos_theta says how close it is, and
// the answers still agree with the oracle.

TEST_F(GimbalLock, FiniteAnswersAndCosThetaReported)
{
  const FixtureBody& body = fixture().body("tet");
  MaxError m_error("gimbal lock: M vs oracle (rel)"), j_error("gimbal lock: J vs oracle (rel)"),
      fd_error("gimbal lock: J vs central differences (rel)");
  for (double theta : { kPi / 2 - 1e-9, kPi / 2, -kPi / 2 })
  {
    SCOPED_TRACE("theta = pi/2 " + std::string(theta == kPi / 2 ? "exactly" : theta < 0 ? "negated" : "- 1e-9"));
    Vector6d q;
    q << 0.3, theta, -1.2, 0.1, 0.2, 0.3;
    const diff_rigid_body_ros::MassMatrices mass = server().massMatrices({ "tet" }, toStdVector(q), true);
    ASSERT_EQ(mass.cos_theta.size(), 1u);
    ASSERT_EQ(mass.M.size(), 1u);
    ASSERT_TRUE(mass.M[0].allFinite());
    for (const Eigen::MatrixXd& dM : mass.dM.at(0))
      ASSERT_TRUE(dM.allFinite());
    EXPECT_EQ(mass.cos_theta[0], std::cos(theta));  // 1e-9 or 6.12e-17: reported, not rounded to 0
    EXPECT_GT(mass.cos_theta[0], 0.0);
    const Matrix6d& M = mass.M[0];
    const Matrix6d expected = refMassMatrix(q, body.mass, body.inertia_body);
    EXPECT_LE(m_error(maxAbs(M - expected) / maxAbs(expected)), kRelativeTolerance) << M << "\nexpected\n" << expected;
    // det(T^T I' T) = cos^2(theta) det(I_b): rank 5 at the lock, but finite.
    const double det = M.topLeftCorner<3, 3>().determinant();
    EXPECT_NEAR(det, std::pow(std::cos(theta), 2) * body.inertia_body.determinant(),
                1e-12 * std::pow(maxAbs(body.inertia_body), 3));

    // The state is accepted and stored exactly; the current-state answers are finite.
    server().setState("tet", q);
    const NamedStates state = server().getState({ "tet" });
    EXPECT_TRUE(bitwiseEqual(state, { { "tet", q } })) << describe(state);
    const diff_rigid_body_ros::MassMatrices current = server().massMatrices({ "tet" }, {}, false);
    ASSERT_EQ(current.cos_theta.size(), 1u);
    EXPECT_EQ(current.cos_theta[0], std::cos(theta));

    const diff_rigid_body_ros::VertexJacobians answer = server().vertexJacobians("tet");
    ASSERT_TRUE(answer.J.allFinite());
    const std::vector<Matrix36d> fd = positionDifferences("tet", q);
    ASSERT_EQ(fd.size(), body.p0.size());
    for (std::size_t v = 0; v < body.p0.size(); ++v)
    {
      const Matrix36d J = answer.jacobian(v);
      EXPECT_LE(j_error(maxAbs(J - refJacobianFromAngularVelocity(q, body.p0[v]))), kRelativeTolerance)
          << "vertex " << v;
      EXPECT_LE(fd_error(maxAbs(J - fd[v])), kFiniteDifferenceTolerance) << "vertex " << v;
    }
    const Vector6d back = server().backprop("tet", Eigen::Matrix3Xd::Ones(3, body.p0.size()));
    for (int j = 0; j < 6; ++j)
      EXPECT_TRUE(std::isfinite(back[j]));
  }
}

}  // namespace drb_rostest
