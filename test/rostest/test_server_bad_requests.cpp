// Bad requests, one test per kind. Each refusal must give success=false (the
// C++ client's ServiceError) and a message naming the problem (body, field,
// index), change nothing (get_state bit for bit equal before and after), and
// leave the node serving. Requests the client cannot build (arrays of a
// wrong size) go out as raw calls.
//
// Runs in bad_requests.test.
#include <cmath>
#include <functional>
#include <initializer_list>
#include <limits>

#include <gtest/gtest.h>

#include "server_under_test.h"

namespace drb_rostest
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// `message` is not empty and mentions every fragment (ignoring case).
void expectMentions(const std::string& message, std::initializer_list<std::string> fragments, const std::string& what)
{
  EXPECT_FALSE(message.empty()) << what;
  for (const std::string& fragment : fragments)
    EXPECT_TRUE(containsIgnoringCase(message, fragment))
        << what << ": message '" << message << "' does not mention '" << fragment << "'";
}

/// The node refuses `call` of the client (ServiceError), naming every fragment.
void expectRefused(const std::function<void()>& call, std::initializer_list<std::string> fragments,
                   const std::string& what)
{
  try
  {
    call();
    ADD_FAILURE() << what << " was accepted";
  }
  catch (const ServiceError& e)
  {
    expectMentions(e.message(), fragments, what);
  }
}

/// The node refuses a raw request: success=false, naming every fragment.
template <typename Response>
void expectRefusedRaw(const Response& response, std::initializer_list<std::string> fragments, const std::string& what)
{
  EXPECT_FALSE(response.success) << what << " was accepted";
  expectMentions(response.message, fragments, what);
}

drb::GetVertexJacobians::Response rawVertexJacobians(const std::string& body, const std::vector<double>& q)
{
  drb::GetVertexJacobians::Request request;
  request.body = body;
  request.q = q;
  return rawServer().call<drb::GetVertexJacobians>("get_vertex_jacobians", request);
}

drb::Backprop::Response rawBackprop(const std::string& body, const std::vector<double>& gradients,
                                    const std::vector<double>& q = {}, const std::vector<std::uint32_t>& vertices = {})
{
  drb::Backprop::Request request;
  request.body = body;
  request.gradients = gradients;
  request.q = q;
  request.vertices = vertices;
  return rawServer().call<drb::Backprop>("backprop", request);
}

class BadRequests : public RestoresState
{
protected:
  void SetUp() override
  {
    RestoresState::SetUp();
    // A distinctive state, so that "unchanged" means something.
    Vector6d brick, tet, roller;
    brick << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
    tet << -3.5, 1.0, 7.25, -0.0, 1e-310, -2.0;
    roller << 100.0, -0.5, 0.5, 1.0, 2.0, 3.0;
    server().setState({ { "brick", brick }, { "tet", tet }, { "roller", roller } });
    before_ = server().getState();
    ASSERT_EQ(before_.size(), 3u);
  }

  void TearDown() override
  {
    // Nothing changed...
    const NamedStates after = server().getState();
    EXPECT_TRUE(bitwiseEqual(before_, after))
        << "state changed by a refused request:\nbefore " << describe(before_) << "\nafter  " << describe(after);
    // ...and the node keeps serving, on the same persistent connections.
    EXPECT_NO_THROW(server().bodies());
    EXPECT_NO_THROW(server().vertexJacobians("tet"));
    EXPECT_NO_THROW(server().massMatrices({}, {}, true));
    EXPECT_NO_THROW(server().backprop("brick", Eigen::Matrix3Xd::Ones(3, 1), nullptr, { 0 }));
    EXPECT_NO_THROW(server().setState({ before_[0] }));
    EXPECT_TRUE(rawVertexJacobians("tet", {}).success);
    EXPECT_TRUE(rawBackprop("brick", std::vector<double>(3, 1.0), {}, { 0 }).success);
    RestoresState::TearDown();
  }

  NamedStates before_;
};

Vector6d sixWith(std::size_t index, double value)
{
  Vector6d q = Vector6d::Constant(0.1);
  q[index] = value;
  return q;
}

std::vector<double> withValueAt(std::vector<double> values, std::size_t index, double value)
{
  values.at(index) = value;
  return values;
}
}  // namespace

TEST_F(BadRequests, UnknownBody)
{
  RigidBodyClient& node = server();
  expectRefused([&] { node.vertexJacobians("nope"); }, { "nope", "unknown" }, "get_vertex_jacobians body 'nope'");
  expectRefused([&] { node.backprop("nope", Eigen::Matrix3Xd(3, 0)); }, { "nope", "unknown" }, "backprop body 'nope'");
  expectRefused(
      [&] {
        node.massMatrices({ "tet", "nope" }, {}, false);
      },
      { "nope", "bodies[1]" }, "get_mass_matrix bodies [tet, nope]");
  expectRefused([&] { node.getState({ "nope" }); }, { "nope" }, "get_state bodies [nope]");
  expectRefused([&] { node.vertexJacobians(""); }, { "unknown" }, "get_vertex_jacobians body ''");
  // All or nothing: the valid first entry is not applied either.
  expectRefused(
      [&] {
        node.setState({ { "tet", Vector6d::Constant(0.5) }, { "nope", Vector6d::Zero() } });
      },
      { "nope", "states[1]" }, "set_state [tet, nope]");
  // A name given twice is ambiguous: refused whole as well.
  expectRefused(
      [&] {
        node.setState({ { "tet", Vector6d::Constant(0.5) }, { "tet", Vector6d::Zero() } });
      },
      { "tet", "states[1]" }, "set_state [tet, tet]");
}

TEST_F(BadRequests, NonFiniteValues)
{
  RigidBodyClient& node = server();
  for (double bad : { kNaN, kInf, -kInf })
  {
    SCOPED_TRACE("value " + std::to_string(bad));
    // q of get_vertex_jacobians, backprop and (batched) get_mass_matrix.
    expectRefused([&] { node.vertexJacobians("tet", sixWith(4, bad)); }, { "q[4]", "finite" },
                  "get_vertex_jacobians q[4]");
    expectRefused([&] { node.backprop("tet", Eigen::Matrix3Xd::Ones(3, 1), sixWith(0, bad), { 2 }); },
                  { "q[0]", "finite" }, "backprop q[0]");
    expectRefused([&] { node.massMatrices({ "tet" }, withValueAt(std::vector<double>(18, 0.1), 13, bad), true); },
                  { "q[13]", "finite" }, "get_mass_matrix q[13]");
    // gradients of backprop: value 5 is vertex 1's z.
    Eigen::Matrix3Xd gradients = Eigen::Matrix3Xd::Ones(3, 2);
    gradients(2, 1) = bad;
    expectRefused(
        [&] {
          node.backprop("brick", gradients, nullptr, { 0, 1 });
        },
        { "gradients[5]", "finite" }, "backprop gradients[5]");
    // set_state: the valid first entry is not applied either.
    expectRefused(
        [&] {
          node.setState({ { "brick", Vector6d::Constant(0.25) }, { "tet", sixWith(2, bad) } });
        },
        { "states[1]", "tet", "finite" }, "set_state states[1].q[2]");
  }
}

TEST_F(BadRequests, WrongArraySizes)
{
  RigidBodyClient& node = server();
  // q: empty or 6 values per configuration (raw: the client sends whole configurations or none).
  for (std::size_t size : { 1u, 5u, 7u, 13u })
  {
    SCOPED_TRACE("q of " + std::to_string(size) + " values");
    expectRefusedRaw(rawVertexJacobians("tet", std::vector<double>(size, 0.1)), { "q", std::to_string(size) },
                     "get_vertex_jacobians q");
    expectRefusedRaw(rawBackprop("tet", std::vector<double>(3, 1.0), std::vector<double>(size, 0.1), { 0 }),
                     { "q", std::to_string(size) }, "backprop q");
  }
  // gradients: 3 per selected vertex (here: all 118 of tet, then a selection of 2).
  expectRefusedRaw(rawBackprop("tet", std::vector<double>(3 * 118 - 1, 1.0)), { "gradients", "353" },
                   "backprop 353 gradients for 118 vertices");
  expectRefused([&] { node.backprop("tet", Eigen::Matrix3Xd::Ones(3, 119)); }, { "gradients", "357" },
                "backprop 357 gradients for 118 vertices");
  expectRefused(
      [&] {
        node.backprop("tet", Eigen::Matrix3Xd::Ones(3, 1), nullptr, { 0, 1 });
      },
      { "gradients" }, "backprop 3 gradients for 2 vertices");
  expectRefused([&] { node.backprop("tet", Eigen::Matrix3Xd(3, 0)); }, { "gradients" }, "backprop without gradients");
  // batched q: a multiple of 6 n.
  expectRefused([&] { node.massMatrices({}, std::vector<double>(6 * 3 + 6, 0.1), false); }, { "q", "24" },
                "get_mass_matrix 24 values for 3 bodies");
  expectRefused(
      [&] {
        node.massMatrices({ "tet", "brick" }, std::vector<double>(6, 0.1), false);
      },
      { "q", "6" }, "get_mass_matrix 6 values for 2 bodies");
  expectRefused([&] { node.massMatrices({ "tet" }, std::vector<double>(13, 0.1), true); }, { "q", "13" },
                "get_mass_matrix 13 values for 1 body");
}

TEST_F(BadRequests, VertexIndexOutOfRange)
{
  RigidBodyClient& node = server();
  // tet has 118 vertices: 117 is the last valid index.
  expectRefused(
      [&] {
        node.vertexJacobians("tet", nullptr, { 0, 118 });
      },
      { "vertices[1]", "118" }, "get_vertex_jacobians vertex 118");
  expectRefused([&] { node.vertexJacobians("tet", nullptr, { 4294967295u }); }, { "vertices[0]", "4294967295" },
                "get_vertex_jacobians vertex 2^32 - 1");
  expectRefused(
      [&] {
        node.backprop("brick", Eigen::Matrix3Xd::Ones(3, 2), nullptr, { 16, 0 });
      },
      { "vertices[0]", "16" }, "backprop vertex 16 of brick's 16");
  // The limit is per body: 63 is valid for roller (64 vertices), not for brick (16).
  EXPECT_NO_THROW(node.vertexJacobians("roller", nullptr, { 63 }));
  expectRefused([&] { node.vertexJacobians("brick", nullptr, { 63 }); }, { "vertices[0]", "63", "brick" },
                "get_vertex_jacobians brick vertex 63");
}

}  // namespace drb_rostest
