// K configurations in one call through the shipped C++ client, against K
// single-configuration calls to the same node on the default scene
// (batched_calls.test): get_vertex_jacobians, get_vertex_jacobians_compact
// (double, float32, positions_only) and backprop, for K = 1, 2 and 7, all
// vertices and a subset with repeats, configurations at and next to gimbal
// lock. Every block must equal its single call bit for bit. The node's state
// is not changed.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include "diff_rigid_body_ros/rigid_body_client.h"

namespace
{
using diff_rigid_body_ros::RigidBodyClient;
using diff_rigid_body_ros::Vector6d;
using diff_rigid_body_ros::VertexJacobians;
using diff_rigid_body_ros::VertexRotationJacobians;

const double kHalfPi = 1.5707963267948966;

// K configurations: generic, at gimbal lock (theta = +-pi/2), one ulp from it, large values.
std::vector<Vector6d> configurations(std::size_t K)
{
  const double table[][6] = {
    { 0.3, -0.4, 1.1, 0.05, -0.1, 0.6 },
    { 0.7, kHalfPi, -0.2, 1.0, 2.0, 3.0 },
    { -1.2, std::nextafter(kHalfPi, 0.0), 2.5, -1e3, 0.0, 7.0 },
    { 2.9, -kHalfPi, 0.4, 0.0, 0.0, 0.0 },
    { 1e6, std::nextafter(-kHalfPi, 0.0), -3e5, 1e8, -1e8, 5e7 },
    { 0.0, 0.0, 0.0, -0.5, 0.5, -0.5 },
    { -0.9, 1.2, 3.1, 4.0, -4.0, 1e-300 },
  };
  std::vector<Vector6d> qs;
  for (std::size_t k = 0; k < K; ++k)
    qs.push_back(Eigen::Map<const Vector6d>(table[k % 7]));
  return qs;
}

// dL/dp for N vertices of configuration k: both signs, mixed magnitudes.
Eigen::Matrix3Xd someGradients(Eigen::Index N, std::size_t k)
{
  Eigen::Matrix3Xd g(3, N);
  for (Eigen::Index i = 0; i < g.size(); ++i)
    g.data()[i] = std::sin(0.7 * static_cast<double>(i) + 1.3 * static_cast<double>(k)) *
                  std::pow(10.0, static_cast<double>(i % 5) - 2.0);
  return g;
}

// Same shape and the same bits (so 0.0 and -0.0 differ).
template <typename A, typename B>
void expectSameBits(const A& batched, const B& single, const std::string& what)
{
  ASSERT_EQ(batched.rows(), single.rows()) << what << ": rows";
  ASSERT_EQ(batched.cols(), single.cols()) << what << ": columns";
  const auto* a = batched.data();
  const auto* b = single.data();
  for (Eigen::Index i = 0; i < batched.size(); ++i)
    ASSERT_EQ(std::memcmp(a + i, b + i, sizeof *a), 0)
        << what << ": value " << i << " differs: batched " << a[i] << ", single " << b[i];
}

class BatchedCalls : public ::testing::Test
{
protected:
  RigidBodyClient client{ ros::NodeHandle(), "/rigid_body_server", ros::Duration(60.0) };

  // Every batched answer for (body, vertices, K) against K single calls.
  void expectBatchedEqualsSingles(const std::string& body, const std::vector<std::uint32_t>& vertices, std::size_t K)
  {
    const std::vector<Vector6d> qs = configurations(K);
    const std::string where = body + ", " + std::to_string(vertices.size()) + " listed vertices, K = " +
                              std::to_string(K);
    const std::vector<VertexJacobians> full = client.vertexJacobians(body, qs, vertices);
    const auto compact = client.vertexJacobiansCompact<double>(body, qs, vertices);
    const auto compact_f32 = client.vertexJacobiansCompact<float>(body, qs, vertices);
    const auto positions_only = client.vertexJacobiansCompact<float>(body, qs, vertices, /*positions_only=*/true);
    ASSERT_EQ(full.size(), K) << where;
    ASSERT_EQ(compact.size(), K) << where;
    ASSERT_EQ(compact_f32.size(), K) << where;
    ASSERT_EQ(positions_only.size(), K) << where;
    const Eigen::Index N = full[0].positions.cols();
    ASSERT_GT(N, 0) << where;
    std::vector<Eigen::Matrix3Xd> dL_dp;
    for (std::size_t k = 0; k < K; ++k)
      dL_dp.push_back(someGradients(N, k));
    const std::vector<Vector6d> gradient = client.backprop(body, dL_dp, qs, vertices);
    ASSERT_EQ(gradient.size(), K) << where;
    for (std::size_t k = 0; k < K; ++k)
    {
      const std::string at = where + ", configuration " + std::to_string(k);
      const VertexJacobians one = client.vertexJacobians(body, qs[k], vertices);
      expectSameBits(full[k].positions, one.positions, "positions, " + at);
      expectSameBits(full[k].J, one.J, "J, " + at);
      const auto compact_one = client.vertexJacobiansCompact<double>(body, qs[k], vertices);
      expectSameBits(compact[k].positions, compact_one.positions, "compact positions, " + at);
      expectSameBits(compact[k].Jr, compact_one.Jr, "compact Jr, " + at);
      const auto f32_one = client.vertexJacobiansCompact<float>(body, qs[k], vertices);
      expectSameBits(compact_f32[k].positions, f32_one.positions, "float32 positions, " + at);
      expectSameBits(compact_f32[k].Jr, f32_one.Jr, "float32 Jr, " + at);
      EXPECT_EQ(positions_only[k].Jr.rows(), 0) << "positions_only sent Jr, " << at;
      expectSameBits(positions_only[k].positions, f32_one.positions, "positions_only, " + at);
      expectSameBits(gradient[k], client.backprop(body, dL_dp[k], qs[k], vertices), "backprop, " + at);
    }
  }
};

TEST_F(BatchedCalls, EqualSingleCallsBitForBit)
{
  for (std::size_t K : { 1u, 2u, 7u })
    for (const std::string body : { "knot", "rock" })
    {
      expectBatchedEqualsSingles(body, {}, K);
      expectBatchedEqualsSingles(body, { 5, 0, 17, 17, 3 }, K);
    }
}

TEST_F(BatchedCalls, RefusalsComeBackAsServiceErrors)
{
  const std::vector<Vector6d> qs = configurations(2);
  try
  {
    client.backprop("rock", { someGradients(2, 0), someGradients(1, 1) }, qs, { 0, 1 });
    ADD_FAILURE() << "backprop accepted 3 gradients for 2 configurations of 2 vertices";
  }
  catch (const diff_rigid_body_ros::ServiceError& e)
  {
    EXPECT_NE(e.message().find("gradients: expected 3 per vertex and configuration = 3 x 2 vertices x 2 "
                               "configurations = 12, got 9 values"),
              std::string::npos)
        << e.message();
  }
  EXPECT_THROW(client.backprop("rock", { someGradients(2, 0) }, qs, { 0, 1 }), std::invalid_argument);
  EXPECT_THROW(client.vertexJacobians("rock", std::vector<Vector6d>{}), std::invalid_argument);
}

}  // namespace

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "batched_calls_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
