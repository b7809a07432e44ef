// The C++ client header with an articulated body (robot_joints_cpp.test): the Franka Panda, one
// fixed-base body of d = 8 coordinates. Shapes follow d; J matches central differences of the
// positions the client returns; backprop equals J^T g; dM/dx_j matches central differences of M;
// set_state/get_state round-trip x bit for bit; a free-body view of the state is refused.
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

}  // namespace

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "robot_joints_cpp");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
