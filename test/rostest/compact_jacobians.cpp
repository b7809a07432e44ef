// ~get_vertex_jacobians_compact through the shipped C++ client, against
// ~get_vertex_jacobians of the same node on the default scene
// (compact_jacobians.test). The oracle is the full answer: J_v = [ Jr_v | I3 ].
//   - double: positions and Jr equal the full answer's positions and first three
//     columns bit for bit, and its last three columns are I3;
//   - float32: every value equals the double one rounded to float32;
//   - positions_only sends no Jr; a vertex subset is rows of the full answer;
//   - refusals carry the message of get_vertex_jacobians.
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
using diff_rigid_body_ros::ServiceError;
using diff_rigid_body_ros::Vector6d;
using diff_rigid_body_ros::VertexJacobians;
using diff_rigid_body_ros::VertexRotationJacobians;

const std::vector<std::string> kBodies{ "knot", "rock" };

Vector6d givenPose()
{
  Vector6d q;
  q << 0.3, -0.4, 1.1, 0.05, -0.1, 0.6;  // rad, m
  return q;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Compact answer `compact` against the full answer `full` of the same request:
// Scalar = double bit for bit, Scalar = float the double values rounded once.
template <typename Scalar>
void expectCompactMatchesFull(const VertexRotationJacobians<Scalar>& compact, const VertexJacobians& full,
                              const std::string& where)
{
  const Eigen::Index n = full.positions.cols();
  ASSERT_EQ(compact.positions.cols(), n) << where << ": vertex count";
  ASSERT_EQ(compact.Jr.rows(), 3 * n) << where << ": Jr rows";
  for (Eigen::Index v = 0; v < n; ++v)
    for (int r = 0; r < 3; ++r)
    {
      ASSERT_TRUE(sameBits(compact.positions(r, v), static_cast<Scalar>(full.positions(r, v))))
          << where << ": position of vertex " << v << ", row " << r << ": " << compact.positions(r, v) << " vs "
          << full.positions(r, v);
      for (int c = 0; c < 3; ++c)
        ASSERT_TRUE(sameBits(compact.Jr(3 * v + r, c), static_cast<Scalar>(full.J(3 * v + r, c))))
            << where << ": Jr of vertex " << v << " (" << r << ", " << c << "): " << compact.Jr(3 * v + r, c)
            << " vs J " << full.J(3 * v + r, c);
    }
}

TEST(CompactJacobians, DoubleIsTheFullAnswerBitForBit)
{
  RigidBodyClient client;
  const Vector6d q = givenPose();
  for (const std::string& body : kBodies)
    for (const Vector6d* pose : { static_cast<const Vector6d*>(nullptr), &q })
    {
      const std::string where = body + (pose ? " at the given q" : " at the current state");
      const VertexJacobians full = client.vertexJacobians(body, pose);
      ASSERT_GT(full.positions.cols(), 0) << where;
      // The reduction is lossless only if the translation block is I3.
      for (Eigen::Index v = 0; v < full.positions.cols(); ++v)
        ASSERT_TRUE((full.jacobian(v).rightCols<3>().array() == Eigen::Matrix3d::Identity().array()).all())
            << where << ": translation block of vertex " << v << " is not I3:\n" << full.jacobian(v);
      expectCompactMatchesFull(client.vertexJacobiansCompact<double>(body, pose), full, where);
    }
}

TEST(CompactJacobians, Float32IsTheDoubleAnswerRounded)
{
  RigidBodyClient client;
  const Vector6d q = givenPose();
  for (const std::string& body : kBodies)
    for (const Vector6d* pose : { static_cast<const Vector6d*>(nullptr), &q })
    {
      const std::string where = body + (pose ? " at the given q (float32)" : " at the current state (float32)");
      expectCompactMatchesFull(client.vertexJacobiansCompact<float>(body, pose), client.vertexJacobians(body, pose),
                               where);
    }
}

TEST(CompactJacobians, PositionsOnlySendsNoRotationJacobians)
{
  RigidBodyClient client;
  const Vector6d q = givenPose();
  const VertexJacobians full = client.vertexJacobians("rock", q);
  const auto compact = client.vertexJacobiansCompact<double>("rock", q, {}, /*positions_only=*/true);
  const auto compact_f32 = client.vertexJacobiansCompact<float>("rock", q, {}, /*positions_only=*/true);
  EXPECT_EQ(compact.Jr.rows(), 0) << "double, positions_only";
  EXPECT_EQ(compact_f32.Jr.rows(), 0) << "float32, positions_only";
  ASSERT_EQ(compact.positions.cols(), full.positions.cols());
  ASSERT_EQ(compact_f32.positions.cols(), full.positions.cols());
  for (Eigen::Index v = 0; v < full.positions.cols(); ++v)
    for (int r = 0; r < 3; ++r)
    {
      ASSERT_TRUE(sameBits(compact.positions(r, v), full.positions(r, v))) << "double, vertex " << v;
      ASSERT_TRUE(sameBits(compact_f32.positions(r, v), static_cast<float>(full.positions(r, v))))
          << "float32, vertex " << v;
    }
}

TEST(CompactJacobians, VertexSubsetIsRowsOfTheFullAnswer)
{
  RigidBodyClient client;
  const Vector6d q = givenPose();
  const VertexJacobians full = client.vertexJacobians("knot", q);
  const std::uint32_t last = static_cast<std::uint32_t>(full.positions.cols() - 1);
  const std::vector<std::uint32_t> subset{ last, 0, 17, 17, 1000 };
  const auto compact = client.vertexJacobiansCompact<double>("knot", q, subset);
  ASSERT_EQ(compact.positions.cols(), static_cast<Eigen::Index>(subset.size()));
  for (std::size_t k = 0; k < subset.size(); ++k)
  {
    const Eigen::Index v = subset[k];
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    for (int r = 0; r < 3; ++r)
    {
      EXPECT_TRUE(sameBits(compact.positions(r, i), full.positions(r, v))) << "subset[" << k << "] = vertex " << v;
      for (int c = 0; c < 3; ++c)
        EXPECT_TRUE(sameBits(compact.Jr(3 * i + r, c), full.J(3 * v + r, c)))
            << "subset[" << k << "] = vertex " << v << ", Jr(" << r << ", " << c << ")";
    }
  }
}

// The message of a refused request, or "" when it was accepted.
template <typename Call>
std::string refusal(Call&& call)
{
  try
  {
    call();
  }
  catch (const ServiceError& e)
  {
    return e.message();
  }
  return "";
}

TEST(CompactJacobians, RefusalsAreThoseOfGetVertexJacobians)
{
  RigidBodyClient client;
  const Vector6d q = givenPose();
  const Vector6d bad_q = (Vector6d() << 0.0, 0.0, std::nan(""), 0.0, 0.0, 0.0).finished();
  struct Case
  {
    std::string situation, body;
    const Vector6d* q;
    std::vector<std::uint32_t> vertices;
  };
  const std::vector<Case> cases{ { "unknown body", "nope", &q, {} },
                                 { "vertex index out of range", "rock", &q, { 0, 99999 } },
                                 { "NaN in q", "knot", &bad_q, {} } };
  for (const Case& c : cases)
  {
    const std::string full = refusal([&] { client.vertexJacobians(c.body, c.q, c.vertices); });
    ASSERT_FALSE(full.empty()) << c.situation << ": get_vertex_jacobians accepted it";
    EXPECT_EQ(refusal([&] { client.vertexJacobiansCompact<double>(c.body, c.q, c.vertices); }), full)
        << c.situation << " (double)";
    EXPECT_EQ(refusal([&] { client.vertexJacobiansCompact<float>(c.body, c.q, c.vertices); }), full)
        << c.situation << " (float32)";
  }
}

}  // namespace

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "compact_jacobians_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
