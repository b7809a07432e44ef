// The C++ client header with an articulated body (robot_joints_cpp.test): the Franka Panda, one
// fixed-base body of d = 8 coordinates. Shapes follow d; J matches central differences of the
// positions the client returns; backprop equals J^T g; dM/dx_j matches central differences of M;
// set_state/get_state round-trip x bit for bit; a free-body view of the state is refused.
// inverseDynamics and forwardDynamics: tau = M a + c + g with M from massMatrix, g = tau(x, 0, 0)
// and c = tau(x, x', 0) - g; FD(ID(a)) = a; dx''/dtau M = I; c = C x'; K configurations in one call
// equal single calls bit for bit; a wrong length throws ServiceError.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "diff_rigid_body_ros/rigid_body_client.h"

namespace
{
using diff_rigid_body_ros::RigidBodyClient;
using diff_rigid_body_ros::Vector6d;

constexpr double kStep = 1e-6;          // [rad or m] central differences
constexpr double kFdTolerance = 1e-6;   // relative to the largest entry
constexpr double kTolerance = 1e-12;    // relative, products of the same numbers
// relative, through M^-1: cond(M) eps with the Panda's cond(M) ~ 1e4 (measured 1.6e-14)
constexpr double kInverseTolerance = 1e-10;

struct Panda
{
  RigidBodyClient client{ ros::NodeHandle(), "rigid_body_server", ros::Duration(100.0) };
  std::string body;
  Eigen::VectorXd x;

  Panda()
  {
    const diff_rigid_body_ros::Bodies bodies = client.bodies();
    body = bodies.names.at(0);
    x.resize(bodies.dofs.at(0));
    for (Eigen::Index k = 0; k < x.size(); ++k)  // 35% .. 70% of the way from lower to upper
      x[k] = bodies.joint_lower[0][k] + (0.35 + 0.05 * k) * (bodies.joint_upper[0][k] - bodies.joint_lower[0][k]);
  }
};

TEST(CppClientArticulated, ShapesFollowTheDofs)
{
  Panda panda;
  ASSERT_EQ(panda.x.size(), 8) << "the Panda's dofs";
  const Eigen::MatrixXd M = panda.client.massMatrix(panda.body, panda.x);
  EXPECT_EQ(M.rows(), 8);
  EXPECT_EQ(M.cols(), 8);
  EXPECT_LE((M - M.transpose()).cwiseAbs().maxCoeff(), kTolerance * M.cwiseAbs().maxCoeff()) << "M symmetric";
  const auto v = panda.client.vertexJacobians(panda.body, panda.x, { 0, 100, 700 });
  EXPECT_EQ(v.J.rows(), 9);
  EXPECT_EQ(v.J.cols(), 8);
  EXPECT_EQ(v.jacobian(2).cols(), 8);
  const auto compact = panda.client.vertexJacobiansCompact<double>(panda.body, panda.x, { 0, 100, 700 });
  EXPECT_EQ(compact.Jr.cols(), 8) << "a fixed base keeps every column";
  EXPECT_EQ(compact.Jr, v.J) << "compact = full for a fixed base";
}

TEST(CppClientArticulated, JacobianAndBackpropAgainstFiniteDifferences)
{
  Panda panda;
  const std::vector<std::uint32_t> vertices = { 0, 151, 300, 500, 800, 1000, 1129 };
  const auto v = panda.client.vertexJacobians(panda.body, panda.x, vertices);
  std::vector<Eigen::VectorXd> steps;
  for (Eigen::Index j = 0; j < panda.x.size(); ++j)
    for (const double sign : { 1.0, -1.0 })
      steps.push_back(panda.x + sign * kStep * Eigen::VectorXd::Unit(panda.x.size(), j));
  const auto moved = panda.client.vertexJacobians(panda.body, steps, vertices);  // one call
  double error = 0.0;
  for (Eigen::Index j = 0; j < panda.x.size(); ++j)
  {
    const Eigen::Matrix3Xd column = (moved[2 * j].positions - moved[2 * j + 1].positions) / (2 * kStep);
    for (std::size_t i = 0; i < vertices.size(); ++i)
      error = std::max(error, (column.col(i) - v.jacobian(i).col(j)).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(error, kFdTolerance * v.J.cwiseAbs().maxCoeff()) << "J vs central differences";
  const Eigen::Matrix3Xd g = Eigen::Matrix3Xd::Random(3, vertices.size());
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(panda.x.size());
  for (std::size_t i = 0; i < vertices.size(); ++i)
    expected += v.jacobian(i).transpose() * g.col(i);
  const Eigen::VectorXd got = panda.client.backprop(panda.body, g, panda.x, vertices);
  ASSERT_EQ(got.size(), panda.x.size());
  EXPECT_LE((got - expected).cwiseAbs().maxCoeff(), kTolerance * expected.cwiseAbs().maxCoeff()) << "J^T g";
}

TEST(CppClientArticulated, MassMatrixDerivatives)
{
  Panda panda;
  const std::vector<double> x(panda.x.data(), panda.x.data() + panda.x.size());
  const diff_rigid_body_ros::MassMatrices answer = panda.client.massMatrices({ panda.body }, x, true);
  ASSERT_EQ(answer.dofs, std::vector<std::uint32_t>{ 8 });
  ASSERT_EQ(answer.dM.at(0).size(), 8u);
  for (Eigen::Index j = 0; j < panda.x.size(); ++j)
  {
    const Eigen::VectorXd e = kStep * Eigen::VectorXd::Unit(panda.x.size(), j);
    const Eigen::MatrixXd fd = (panda.client.massMatrix(panda.body, panda.x + e) -
                                panda.client.massMatrix(panda.body, panda.x - e)) / (2 * kStep);
    EXPECT_LE((fd - answer.dM[0][j]).cwiseAbs().maxCoeff(), kFdTolerance * answer.at(0, 0).cwiseAbs().maxCoeff())
        << "dM/dx_" << j;
  }
}

TEST(CppClientArticulated, StatesOfDofValues)
{
  Panda panda;
  const diff_rigid_body_ros::BodyStates before = panda.client.getState();
  panda.client.setState(panda.body, panda.x);
  const diff_rigid_body_ros::BodyStates after = panda.client.getState({ panda.body });
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(after[0].second, panda.x) << "x round-trips bit for bit";
  using FreeStates = std::vector<std::pair<std::string, Vector6d>>;
  EXPECT_THROW((void)FreeStates(after), std::length_error) << "an 8-coordinate state is not a free body's q";
  EXPECT_THROW(panda.client.setState(panda.body, Vector6d::Zero()), diff_rigid_body_ros::ServiceError)
      << "6 values for an 8-dof body";
  panda.client.setState(before);
}

/// max |a - b| / max(|a|, |b|).
double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b)
{
  return (a - b).cwiseAbs().maxCoeff() / std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
}

TEST(CppClientArticulated, DynamicsIdentities)
{
  Panda panda;
  const Eigen::Index d = panda.x.size();
  const Eigen::VectorXd xdot = Eigen::VectorXd::LinSpaced(d, -0.8, 0.9);
  const Eigen::VectorXd xddot = Eigen::VectorXd::LinSpaced(d, 1.5, -1.2);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(d);
  const auto id = panda.client.inverseDynamics(panda.body, panda.x, xdot, xddot, /*derivatives=*/true);
  ASSERT_EQ(id.tau.size(), 1u);
  ASSERT_EQ(id.tau[0].size(), d);
  ASSERT_EQ(id.dtau_dq.size(), 1u);
  EXPECT_EQ(id.dtau_dq[0].rows(), d);
  EXPECT_TRUE(id.coriolis_matrices.empty()) << "C was not asked for";
  const Eigen::MatrixXd M = panda.client.massMatrix(panda.body, panda.x);
  const Eigen::VectorXd g = panda.client.inverseDynamics(panda.body, panda.x, zero, zero).tau[0];
  const Eigen::VectorXd c = panda.client.inverseDynamics(panda.body, panda.x, xdot, zero).tau[0] - g;
  EXPECT_LE(relativeError(id.tau[0], M * xddot + c + g), kTolerance) << "tau = M a + c + g";
  EXPECT_LE(relativeError(id.gravity_terms[0], g), kTolerance) << "g = tau(x, 0, 0)";
  EXPECT_LE(relativeError(id.velocity_terms[0], c), kTolerance) << "c = tau(x, x', 0) - g";

  const auto fd = panda.client.forwardDynamics(panda.body, panda.x, xdot, id.tau[0], /*derivatives=*/true);
  ASSERT_EQ(fd.qddot.size(), 1u);
  EXPECT_LE(relativeError(fd.qddot[0], xddot), kInverseTolerance) << "FD(ID(a)) = a";
  EXPECT_LE(relativeError(fd.dqddot_dtau[0] * M, Eigen::MatrixXd::Identity(d, d)), kInverseTolerance)
      << "dx''/dtau M = I";

  const std::vector<double> x(panda.x.data(), panda.x.data() + d), v(xdot.data(), xdot.data() + d);
  const auto with_c = panda.client.inverseDynamics({ panda.body }, x, v, {}, /*coriolis_matrices=*/true);
  ASSERT_EQ(with_c.coriolis_matrices.size(), 1u);
  EXPECT_LE(relativeError(with_c.coriolis_matrices[0] * xdot, c), kTolerance) << "c = C x'";
}

TEST(CppClientArticulated, DynamicsOfSeveralConfigurations)
{
  Panda panda;
  const Eigen::Index d = panda.x.size();
  std::vector<double> q, qdot, qddot;
  for (int k = 0; k < 3; ++k)
    for (Eigen::Index j = 0; j < d; ++j)
    {
      q.push_back(panda.x[j] + 0.05 * k);
      qdot.push_back(0.1 * (j - k));
      qddot.push_back(0.2 * (k + 1) - 0.1 * j);
    }
  const auto all = panda.client.inverseDynamics({ panda.body }, q, qdot, qddot, true, true);
  ASSERT_EQ(all.configurations, 3u);
  ASSERT_EQ(all.tau.size(), 3u);
  std::vector<double> tau;
  for (const Eigen::VectorXd& one : all.tau)
    tau.insert(tau.end(), one.data(), one.data() + one.size());
  const auto forward = panda.client.forwardDynamics({ panda.body }, q, qdot, tau, true);
  ASSERT_EQ(forward.qddot.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k)
  {
    const auto slice = [&](const std::vector<double>& values) {
      return std::vector<double>(values.begin() + k * d, values.begin() + (k + 1) * d);
    };
    const std::size_t m = all.index(k, 0);
    const auto one = panda.client.inverseDynamics({ panda.body }, slice(q), slice(qdot), slice(qddot), true, true);
    EXPECT_EQ(all.tau[m], one.tau[0]) << "configuration " << k;
    EXPECT_EQ(all.coriolis_matrices[m], one.coriolis_matrices[0]) << "configuration " << k;
    EXPECT_EQ(all.dtau_dq[m], one.dtau_dq[0]) << "configuration " << k;
    EXPECT_EQ(all.dtau_dqdot[m], one.dtau_dqdot[0]) << "configuration " << k;
    const auto one_forward = panda.client.forwardDynamics({ panda.body }, slice(q), slice(qdot), slice(tau), true);
    EXPECT_EQ(forward.qddot[m], one_forward.qddot[0]) << "configuration " << k;
    EXPECT_EQ(forward.dqddot_dq[m], one_forward.dqddot_dq[0]) << "configuration " << k;
    const std::vector<double> a = slice(qddot);
    EXPECT_LE(relativeError(forward.qddot[m], Eigen::Map<const Eigen::VectorXd>(a.data(), d)), kInverseTolerance)
        << "FD(ID(a)) = a, configuration " << k;
  }
  EXPECT_THROW(panda.client.forwardDynamics({}, q, std::vector<double>(q.size() - 1, 0.0)),
               diff_rigid_body_ros::ServiceError)
      << "qdot one value short";
  EXPECT_THROW(panda.client.inverseDynamics({ "nope" }, q), diff_rigid_body_ros::ServiceError)
      << "an unknown body";
}

}  // namespace

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "robot_joints_cpp");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
