// The C++ client header (include/diff_rigid_body_ros/rigid_body_client.h)
// against the real node on the default scene (clients_cpp.test): Eigen
// shapes, layout, errors, and a Gauss-Newton pose fit built on it.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "diff_rigid_body_ros/rigid_body_client.h"
#include "diff_rigid_body_ros/rigid_body_pool.h"
#include "../support/expect_throws.h"

namespace
{
using diff_rigid_body_ros::Matrix6d;
using diff_rigid_body_ros::RigidBodyClient;
using diff_rigid_body_ros::Vector6d;

constexpr double MATRIX_TOLERANCE = 1e-12;   // relative, of the largest entry
constexpr double FD_TOLERANCE = 1e-7;        // m per unit of q (central differences, h = 1e-6)
constexpr double FIT_TOLERANCE = 1e-8;       // rad and m

// Whether `frameJacobians(body, q, {a, b}, {"c"})` compiles for Client, with a and b of type Element
// (two names, or two numbers: qdot).
template <typename Client, typename Element>
constexpr auto acceptsBracedQdot(int)
    -> decltype(std::declval<Client&>().frameJacobians(std::string(), std::vector<double>(), { Element(), Element() },
                                                       std::vector<std::string>{ "c" }),
                true)
{
  return true;
}
template <typename Client, typename Element>
constexpr bool acceptsBracedQdot(long)
{
  return false;
}

Vector6d hiddenPose()
{
  Vector6d q;
  q << 0.3, -0.4, 1.1, 0.05, -0.1, 0.6;
  return q;
}

TEST(CppClient, BodiesOfTheDefaultScene)
{
  RigidBodyClient client;
  const diff_rigid_body_ros::Bodies bodies = client.bodies();
  EXPECT_EQ(bodies.fixed_frame, "world");
  ASSERT_EQ(bodies.names, (std::vector<std::string>{ "knot", "rock" }));
  EXPECT_EQ(bodies.vertex_counts.at(0), 4096u);
  EXPECT_NEAR(bodies.masses.at(0), 0.28125334, 1e-12);
  EXPECT_NEAR(bodies.inertias.at(0)(2, 2), 6.0365524e-04, 1e-12);
  // Links in vertex order: the rock's own link, then its merged handle (masses from the URDF).
  ASSERT_EQ(bodies.links.size(), 2u);
  ASSERT_EQ(bodies.links.at(1).size(), 2u);
  EXPECT_EQ(bodies.links[1][0].name, "rock");
  EXPECT_EQ(bodies.links[1][0].mass, 1.39997);
  EXPECT_EQ(bodies.links[1][1].name, "rock_handle");
  EXPECT_EQ(bodies.links[1][1].mass, 0.05);
  EXPECT_EQ(bodies.links[1][1].first_vertex, bodies.links[1][0].vertex_count);
  EXPECT_EQ(bodies.links[1][0].vertex_count + bodies.links[1][1].vertex_count, bodies.vertex_counts.at(1));
  EXPECT_EQ(bodies.dofs, (std::vector<std::uint32_t>{ 6, 6 }));
}

TEST(CppClient, BatchedMassMatricesMatchSingleCallsAndLayout)
{
  RigidBodyClient client;
  const std::vector<std::string> names{ "knot", "rock" };
  std::vector<double> q;  // K = 3 configurations of both bodies
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 2; ++i)
      for (int c = 0; c < 6; ++c)
        q.push_back(0.1 * (k + 1) * (c + 1) - 0.2 * i);
  const auto batch = client.massMatrices(names, q, /*derivatives=*/true);
  ASSERT_EQ(batch.configurations, 3u);
  ASSERT_EQ(batch.M.size(), 6u);
  ASSERT_EQ(batch.dM.size(), 6u);
  const auto bodies = client.bodies();
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < 2; ++i)
    {
      Vector6d qi = Eigen::Map<const Vector6d>(q.data() + (k * 2 + i) * 6);
      const Matrix6d single = client.massMatrix(names[i], qi);
      EXPECT_LE((batch.at(k, i) - single).cwiseAbs().maxCoeff(), MATRIX_TOLERANCE * single.cwiseAbs().maxCoeff());
      // Lower block m I3; dM/dpsi = 0.
      EXPECT_NEAR(batch.at(k, i)(3, 3), bodies.masses[i], 1e-12);
      EXPECT_EQ(batch.dM[k * 2 + i][2].cwiseAbs().maxCoeff(), 0.0);
      EXPECT_NEAR(batch.cos_theta[k * 2 + i], std::cos(qi[1]), 1e-15);
    }
}

TEST(CppClient, FrameJacobiansOfAFreeBodyAndItsMergedLink)
{
  // The rock at K = 2 configurations: its link and its merged handle move rigidly with it, so
  // d(origin)/dt = I3, the angular rows do not depend on t, and v = w x (p - t) for the rotation
  // columns; the rock's link origin is t - R c (c = get_bodies' com_offset: t is the COM).
  RigidBodyClient client;
  const auto bodies = client.bodies();
  std::vector<double> q{ 0.3, -0.4, 1.1, 0.05, -0.1, 0.6, -0.7, 0.2, 0.4, 1.0, 2.0, -3.0 };
  const auto answer = client.frameJacobians("rock", q, {}, {}, diff_rigid_body_ros::FrameReference::LocalWorldAligned);
  ASSERT_EQ(answer.frames, (std::vector<std::string>{ "rock", "rock_handle" }));
  ASSERT_EQ(answer.configurations, 2u);
  ASSERT_EQ(answer.J.size(), 4u);
  EXPECT_TRUE(answer.bias.empty());
  for (std::size_t k = 0; k < 2; ++k)
  {
    const Eigen::Vector3d t = Eigen::Map<const Eigen::Vector3d>(q.data() + 6 * k + 3);
    const Eigen::Matrix3d R = answer.poses[answer.index(k, 0)].linear();
    EXPECT_LT((answer.poses[answer.index(k, 0)].translation() - (t - R * bodies.com_offsets[1])).norm(), 1e-14);
    for (std::size_t f = 0; f < 2; ++f)
    {
      const auto& J = answer.J[answer.index(k, f)];
      const Eigen::Vector3d r = answer.poses[answer.index(k, f)].translation() - t;
      Eigen::Matrix3d r_cross;
      r_cross << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
      EXPECT_LT((J.block<3, 3>(0, 3) - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
      EXPECT_EQ((J.block<3, 3>(3, 3).cwiseAbs().maxCoeff()), 0.0);
      EXPECT_LT((J.block<3, 3>(0, 0) + r_cross * J.block<3, 3>(3, 0)).cwiseAbs().maxCoeff(), 1e-14);
    }
  }
}

TEST(CppClient, CenterOfMassOfFreeBodiesIsTheirTranslation)
{
  RigidBodyClient client;
  const std::vector<double> q{ 0.3, -0.4, 1.1, 0.05, -0.1, 0.6, -0.7, 0.2, 0.4, 1.0, 2.0, -3.0 };
  const auto answer = client.centerOfMass({ "knot", "rock" }, q, {}, /*jacobians=*/true);
  ASSERT_EQ(answer.configurations, 1u);
  ASSERT_EQ(answer.J.size(), 2u);
  const auto bodies = client.bodies();
  for (std::size_t i = 0; i < 2; ++i)
  {
    EXPECT_EQ(answer.masses[i], bodies.masses[i]);
    EXPECT_EQ(answer.com[i], (Eigen::Map<const Eigen::Vector3d>(q.data() + 6 * i + 3)));
    EXPECT_EQ(answer.J[i].leftCols(3).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(answer.J[i].rightCols(3), Eigen::Matrix3d::Identity());
    EXPECT_EQ(answer.bias[i], Eigen::Vector3d::Zero());
  }
  DRB_EXPECT_THROWS_MESSAGE(client.centerOfMass({ "nothing" }), diff_rigid_body_ros::ServiceError,
                            "unknown body 'nothing'");
}

TEST(CppClient, BatchedCallsTakeOneEigenVectorPerConfiguration)
{
  // massMatrices, inverseDynamics and forwardDynamics take std::vector<Vector6d> (or VectorXd), as
  // vertexJacobians and backprop do: the same answer, bit for bit, as K configurations concatenated.
  RigidBodyClient client;
  std::vector<Vector6d> qs, qdots;
  std::vector<Eigen::VectorXd> qs_dynamic;
  std::vector<double> flat, flat_qdot;
  for (int k = 0; k < 3; ++k)
  {
    Vector6d q, qdot;
    for (int c = 0; c < 6; ++c)
      q[c] = 0.1 * (k + 1) * (c + 1), qdot[c] = 0.2 * (c - k);
    qs.push_back(q), qdots.push_back(qdot), qs_dynamic.push_back(q);
    flat.insert(flat.end(), q.data(), q.data() + 6);
    flat_qdot.insert(flat_qdot.end(), qdot.data(), qdot.data() + 6);
  }
  const auto M = client.massMatrices({ "knot" }, flat, true);
  const auto M6 = client.massMatrices({ "knot" }, qs, true), MX = client.massMatrices({ "knot" }, qs_dynamic, true);
  ASSERT_EQ(M6.configurations, 3u);
  for (std::size_t k = 0; k < 3; ++k)
  {
    EXPECT_EQ(M6.at(k, 0), M.at(k, 0));
    EXPECT_EQ(MX.at(k, 0), M.at(k, 0));
    EXPECT_EQ(M6.dM[k][4], M.dM[k][4]);
  }
  const auto tau = client.inverseDynamics({ "knot" }, flat, flat_qdot);
  const auto tau6 = client.inverseDynamics({ "knot" }, qs, qdots);
  const auto qddot = client.forwardDynamics({ "knot" }, flat, flat_qdot);
  const auto qddot6 = client.forwardDynamics({ "knot" }, qs, qdots);
  ASSERT_EQ(tau6.tau.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k)
  {
    EXPECT_EQ(tau6.tau[k], tau.tau[k]);
    EXPECT_EQ(qddot6.qddot[k], qddot.qddot[k]);
  }
  // The earlier orders (client_earlier_orders.h, deprecated) still compile and give the same bits.
  constexpr auto World = diff_rigid_body_ros::FrameReference::World;
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  const auto earlier_tau = client.inverseDynamics(flat, flat_qdot, {}, { "knot" });
  const auto earlier_tau6 = client.inverseDynamics(qs, qdots, {}, { "knot" });
  const auto earlier_qddot = client.forwardDynamics(flat, flat_qdot, {}, { "knot" });
  const auto earlier_qddot6 = client.forwardDynamics(qs, qdots, {}, { "knot" });
  const std::vector<std::string> frames = client.frameJacobians("knot", flat).frames;
  const auto earlier_frames = client.frameJacobians("knot", flat, frames, World, flat_qdot, true);
  const auto earlier_braced = client.frameJacobians("knot", flat, { "knot" }, World, flat_qdot, true);
  // Two names would fit qdot's iterator-pair constructor as well: the names must win.
  const auto earlier_two = client.frameJacobians("knot", flat, { "knot", "knot" });
  const std::string knot = "knot";
  const auto earlier_mixed = client.frameJacobians("knot", flat, { knot, "knot" });
#pragma GCC diagnostic pop
  const auto frames_now = client.frameJacobians("knot", flat, flat_qdot, frames, World, true);
  const auto braced_now = client.frameJacobians("knot", flat, flat_qdot, { "knot" }, World, true);
  const auto empty_qdot = client.frameJacobians("knot", flat, {}, { "knot" }, World);  // {} is qdot: the current order
  const auto two_now = client.frameJacobians("knot", flat, {}, { "knot", "knot" });
  // Two names where qdot goes, then frames, fit neither order: they must not compile.
  static_assert(!acceptsBracedQdot<RigidBodyClient, const char*>(0), "names as qdot, then frames, compile");
  static_assert(!acceptsBracedQdot<diff_rigid_body_ros::RigidBodyPool, const char*>(0), "names as qdot compile (pool)");
  static_assert(acceptsBracedQdot<RigidBodyClient, double>(0), "braced numbers as qdot must still compile");
  ASSERT_EQ(two_now.frames.size(), 2u);
  ASSERT_EQ(earlier_two.frames, two_now.frames);
  ASSERT_EQ(earlier_mixed.frames, two_now.frames);
  EXPECT_EQ(earlier_two.J, two_now.J);
  EXPECT_EQ(earlier_mixed.J, two_now.J);
  ASSERT_EQ(earlier_braced.frames, std::vector<std::string>{ "knot" });
  ASSERT_EQ(empty_qdot.frames, std::vector<std::string>{ "knot" });
  for (std::size_t k = 0; k < 3; ++k)
  {
    EXPECT_EQ(earlier_tau.tau[k], tau.tau[k]);
    EXPECT_EQ(earlier_tau6.tau[k], tau.tau[k]);
    EXPECT_EQ(earlier_qddot.qddot[k], qddot.qddot[k]);
    EXPECT_EQ(earlier_qddot6.qddot[k], qddot.qddot[k]);
    EXPECT_EQ(earlier_frames.J[k], frames_now.J[k]);
    EXPECT_EQ(earlier_frames.bias[k], frames_now.bias[k]);
    EXPECT_EQ(earlier_braced.J[k], braced_now.J[k]);
    EXPECT_EQ(earlier_braced.bias[k], braced_now.bias[k]);
    EXPECT_EQ(empty_qdot.J[k], braced_now.J[k]);
  }
}

TEST(CppClient, JacobiansMatchFiniteDifferencesAndBackprop)
{
  RigidBodyClient client;
  const Vector6d q = hiddenPose();
  const std::vector<std::uint32_t> vertices{ 0, 17, 4095 };
  const auto answer = client.vertexJacobians("knot", q, vertices);
  ASSERT_EQ(answer.positions.cols(), 3);
  ASSERT_EQ(answer.J.rows(), 9);
  const double h = 1e-6;
  for (int j = 0; j < 6; ++j)
  {
    Vector6d plus = q, minus = q;
    plus[j] += h;
    minus[j] -= h;
    const Eigen::Matrix3Xd column = (client.vertexJacobians("knot", plus, vertices).positions -
                                     client.vertexJacobians("knot", minus, vertices).positions) /
                                    (2 * h);
    for (int v = 0; v < 3; ++v)
      EXPECT_LE((answer.jacobian(v).col(j) - column.col(v)).cwiseAbs().maxCoeff(), FD_TOLERANCE)
          << "vertex " << vertices[v] << ", column " << j;
  }
  Eigen::Matrix3Xd g(3, 3);
  g << 1, 0, 2, 0, -1, 0.5, 3, 1, 0;
  const Vector6d expected = answer.J.transpose() * Eigen::Map<const Eigen::VectorXd>(g.data(), 9);
  EXPECT_LE((client.backprop("knot", g, q, vertices) - expected).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(CppClient, RefusalThrowsServiceErrorWithTheNodesMessage)
{
  RigidBodyClient client;
  try
  {
    client.vertexJacobians("no_such_body");
    FAIL() << "no exception";
  }
  catch (const diff_rigid_body_ros::ServiceError& e)
  {
    EXPECT_NE(e.message().find("no_such_body"), std::string::npos) << e.message();
    EXPECT_NE(e.service().find("get_vertex_jacobians"), std::string::npos) << e.service();
  }
  // The client still works after a refusal.
  EXPECT_EQ(client.bodies().names.size(), 2u);
}

TEST(CppClient, AWrongNodeNameSaysNoNodeThere)
{
  RigidBodyClient client(ros::NodeHandle(), "/rigid_body_srever", ros::Duration(1.0));
  DRB_EXPECT_THROWS_MESSAGE(client.bodies(), diff_rigid_body_ros::ConnectionError,
                            "no node at /rigid_body_srever (is it running? rosnode list)",
                            "/rigid_body_srever/get_bodies");
}

TEST(CppClient, GaussNewtonRecoversAHiddenPose)
{
  RigidBodyClient client;
  const Vector6d hidden = hiddenPose();
  const Eigen::Matrix3Xd target = client.vertexJacobians("rock", hidden).positions;
  Vector6d q = hidden;
  q.head<3>() += Eigen::Vector3d(0.3, -0.2, 0.25);  // about 26 degrees
  q.tail<3>() += Eigen::Vector3d(0.1, 0.15, -0.08);  // 0.2 m
  int iterations = 0;
  for (; iterations < 30; ++iterations)
  {
    const auto answer = client.vertexJacobians("rock", q);
    const Eigen::Matrix3Xd residual = answer.positions - target;
    const Eigen::Map<const Eigen::VectorXd> r(residual.data(), residual.size());
    const Vector6d step = answer.J.colPivHouseholderQr().solve(-r);
    q += step;
    if (step.cwiseAbs().maxCoeff() < 1e-13)
      break;
  }
  EXPECT_LT(iterations, 30);
  EXPECT_LE((q - hidden).cwiseAbs().maxCoeff(), FIT_TOLERANCE) << "q = " << q.transpose();
}

}  // namespace

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "clients_cpp_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
