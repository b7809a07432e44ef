// Bad requests, one test per kind. Each refusal must give success=false and a
// message naming the problem (body, field, index), change nothing (get_state
// bit for bit equal before and after), and leave the node serving.
//
// Runs in bad_requests.test.
#include <cmath>
#include <initializer_list>
#include <limits>

#include <gtest/gtest.h>

#include "server_client.h"

namespace drb_rostest
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

class BadRequests : public ::testing::Test
{
protected:
  void SetUp() override
  {
    // A distinctive state, so that "unchanged" means something.
    Vector6d brick, tet, roller;
    brick << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
    tet << -3.5, 1.0, 7.25, -0.0, 1e-310, -2.0;
    roller << 100.0, -0.5, 0.5, 1.0, 2.0, 3.0;
    ASSERT_TRUE(
        server().setState({ bodyState("brick", brick), bodyState("tet", tet), bodyState("roller", roller) }).success);
    const drb::GetState::Response before = server().getState();
    ASSERT_TRUE(before.success) << before.message;
    before_ = before.states;
    ASSERT_EQ(before_.size(), 3u);
  }

  void TearDown() override
  {
    // Nothing changed...
    const drb::GetState::Response after = server().getState();
    ASSERT_TRUE(after.success) << after.message;
    EXPECT_TRUE(bitwiseEqual(before_, after.states))
        << "state changed by a refused request:\nbefore " << describe(before_) << "\nafter  " << describe(after.states);
    // ...and the node keeps serving, on the same persistent connections.
    EXPECT_TRUE(server().getBodies().success);
    EXPECT_TRUE(server().getVertexJacobians("tet").success);
    EXPECT_TRUE(server().getMassMatrix({}, {}, true).success);
    EXPECT_TRUE(server().backprop("brick", std::vector<double>(3, 1.0), {}, { 0 }).success);
    EXPECT_TRUE(server().setState({ before_[0] }).success);
  }

  /// success=false, and the message mentions every fragment (ignoring case).
  template <typename Response>
  void expectRefused(const Response& response, std::initializer_list<std::string> fragments, const std::string& what)
  {
    EXPECT_FALSE(response.success) << what << " was accepted";
    EXPECT_FALSE(response.message.empty()) << what;
    for (const std::string& fragment : fragments)
      EXPECT_TRUE(containsIgnoringCase(response.message, fragment))
          << what << ": message '" << response.message << "' does not mention '" << fragment << "'";
  }

  std::vector<drb::BodyState> before_;
};

std::vector<double> sixValues(double fill = 0.1)
{
  return std::vector<double>(6, fill);
}

std::vector<double> withValueAt(std::vector<double> values, std::size_t index, double value)
{
  values.at(index) = value;
  return values;
}
}  // namespace

TEST_F(BadRequests, UnknownBody)
{
  expectRefused(server().getVertexJacobians("nope"), { "nope", "unknown" }, "get_vertex_jacobians body 'nope'");
  expectRefused(server().backprop("nope", {}), { "nope", "unknown" }, "backprop body 'nope'");
  expectRefused(server().getMassMatrix({ "tet", "nope" }, {}, false), { "nope", "bodies[1]" },
                "get_mass_matrix bodies [tet, nope]");
  expectRefused(server().getState({ "nope" }), { "nope" }, "get_state bodies [nope]");
  expectRefused(server().getVertexJacobians(""), { "unknown" }, "get_vertex_jacobians body ''");
  // All or nothing: the valid first entry is not applied either.
  expectRefused(server().setState({ bodyState("tet", Vector6d::Constant(0.5)), bodyState("nope", Vector6d::Zero()) }),
                { "nope", "states[1]" }, "set_state [tet, nope]");
  // A name given twice is ambiguous: refused whole as well.
  expectRefused(server().setState({ bodyState("tet", Vector6d::Constant(0.5)), bodyState("tet", Vector6d::Zero()) }),
                { "tet", "states[1]" }, "set_state [tet, tet]");
}

TEST_F(BadRequests, NonFiniteValues)
{
  for (double bad : { kNaN, kInf, -kInf })
  {
    SCOPED_TRACE("value " + std::to_string(bad));
    // q of get_vertex_jacobians, backprop and (batched) get_mass_matrix.
    expectRefused(server().getVertexJacobians("tet", withValueAt(sixValues(), 4, bad)), { "q[4]", "finite" },
                  "get_vertex_jacobians q[4]");
    expectRefused(server().backprop("tet", std::vector<double>(3, 1.0), withValueAt(sixValues(), 0, bad), { 2 }),
                  { "q[0]", "finite" }, "backprop q[0]");
    expectRefused(server().getMassMatrix({ "tet" }, withValueAt(std::vector<double>(18, 0.1), 13, bad), true),
                  { "q[13]", "finite" }, "get_mass_matrix q[13]");
    // gradients of backprop.
    expectRefused(server().backprop("brick", withValueAt(std::vector<double>(6, 1.0), 5, bad), {}, { 0, 1 }),
                  { "gradients[5]", "finite" }, "backprop gradients[5]");
    // set_state: the valid first entry is not applied either.
    expectRefused(server().setState({ bodyState("brick", Vector6d::Constant(0.25)),
                                      bodyState("tet", Eigen::Map<const Vector6d>(withValueAt(sixValues(), 2, bad).data())) }),
                  { "states[1]", "tet", "finite" }, "set_state states[1].q[2]");
  }
}

TEST_F(BadRequests, WrongArraySizes)
{
  // q: 6 values or empty.
  for (std::size_t size : { 1u, 5u, 7u, 12u })
  {
    SCOPED_TRACE("q of " + std::to_string(size) + " values");
    expectRefused(server().getVertexJacobians("tet", std::vector<double>(size, 0.1)),
                  { "q", std::to_string(size) }, "get_vertex_jacobians q");
    expectRefused(server().backprop("tet", std::vector<double>(3, 1.0), std::vector<double>(size, 0.1), { 0 }),
                  { "q", std::to_string(size) }, "backprop q");
  }
  // gradients: 3 per selected vertex (here: all 118 of tet, then a selection of 2).
  expectRefused(server().backprop("tet", std::vector<double>(3 * 118 - 1, 1.0)), { "gradients", "353" },
                "backprop 353 gradients for 118 vertices");
  expectRefused(server().backprop("tet", std::vector<double>(3 * 118 + 3, 1.0)), { "gradients", "357" },
                "backprop 357 gradients for 118 vertices");
  expectRefused(server().backprop("tet", std::vector<double>(3, 1.0), {}, { 0, 1 }), { "gradients" },
                "backprop 3 gradients for 2 vertices");
  expectRefused(server().backprop("tet", {}), { "gradients" }, "backprop without gradients");
  // batched q: a multiple of 6 n.
  expectRefused(server().getMassMatrix({}, std::vector<double>(6 * 3 + 6, 0.1), false), { "q", "24" },
                "get_mass_matrix 24 values for 3 bodies");
  expectRefused(server().getMassMatrix({ "tet", "brick" }, std::vector<double>(6, 0.1), false), { "q", "6" },
                "get_mass_matrix 6 values for 2 bodies");
  expectRefused(server().getMassMatrix({ "tet" }, std::vector<double>(13, 0.1), true), { "q", "13" },
                "get_mass_matrix 13 values for 1 body");
}

TEST_F(BadRequests, VertexIndexOutOfRange)
{
  // tet has 118 vertices: 117 is the last valid index.
  expectRefused(server().getVertexJacobians("tet", {}, { 0, 118 }), { "vertices[1]", "118" },
                "get_vertex_jacobians vertex 118");
  expectRefused(server().getVertexJacobians("tet", {}, { 4294967295u }), { "vertices[0]", "4294967295" },
                "get_vertex_jacobians vertex 2^32 - 1");
  expectRefused(server().backprop("brick", std::vector<double>(6, 1.0), {}, { 16, 0 }), { "vertices[0]", "16" },
                "backprop vertex 16 of brick's 16");
  // The limit is per body: 63 is valid for roller (64 vertices), not for brick (16).
  EXPECT_TRUE(server().getVertexJacobians("roller", {}, { 63 }).success);
  expectRefused(server().getVertexJacobians("brick", {}, { 63 }), { "vertices[0]", "63", "brick" },
                "get_vertex_jacobians brick vertex 63");
}

}  // namespace drb_rostest
