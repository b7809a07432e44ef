// The node's boundaries (src/node/server_helpers.h): a service handler, a
// topic or timer callback, and the start-up (loading the scene, starting the
// server). Whatever `work` throws there, a core Error or a foreign
// std::exception (a bug), becomes a message that names where it happened;
// nothing reaches roscpp or std::terminate. No master is needed: the helpers
// only log.
#include <new>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <gtest/gtest.h>

#include <diff_rigid_body/GetMassMatrix.h>

#include "diff_rigid_body/exceptions.h"
#include "../../src/node/server_helpers.h"

namespace drb = diff_rigid_body;
using drb::node::guardCallback;
using drb::node::runAtStart;
using drb::node::serve;

namespace
{
/// What an unordered_map::at of a missing key throws: issue 22's abort.
void throwOutOfRange()
{
  const std::unordered_map<std::string, int> empty;
  static_cast<void>(empty.at("c"));
}
}  // namespace

TEST(NodeBoundaries, ServiceTurnsAForeignExceptionIntoARefusalNamingTheService)
{
  drb::GetMassMatrix::Response response;
  EXPECT_TRUE(serve(response, "get_mass_matrix", [&] {
    response.mass_matrices.assign(36, 1.0);  // a partial answer must not leak out
    throwOutOfRange();
  }));
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message.rfind("internal error in get_mass_matrix: ", 0), 0u) << response.message;
  EXPECT_NE(response.message.find("(std::out_of_range)"), std::string::npos) << response.message;
  EXPECT_TRUE(response.mass_matrices.empty());
}

TEST(NodeBoundaries, ServiceKeepsACoreErrorsMessage)
{
  drb::GetMassMatrix::Response response;
  EXPECT_TRUE(serve(response, "get_mass_matrix", [] { throw drb::InvalidArgumentError("q[3]: not finite (nan)"); }));
  EXPECT_FALSE(response.success);
  EXPECT_EQ(response.message, "q[3]: not finite (nan)");
}

TEST(NodeBoundaries, ServiceAnswersBadAllocAsAnInternalError)
{
  drb::GetMassMatrix::Response response;
  EXPECT_TRUE(serve(response, "backprop", [] { throw std::bad_alloc(); }));
  EXPECT_FALSE(response.success);
  EXPECT_NE(response.message.find("internal error in backprop: "), std::string::npos) << response.message;
  EXPECT_NE(response.message.find("std::bad_alloc"), std::string::npos) << response.message;
}

TEST(NodeBoundaries, ServiceThatReturnsSucceeds)
{
  drb::GetMassMatrix::Response response;
  EXPECT_TRUE(serve(response, "get_mass_matrix", [&] { response.dofs.push_back(6); }));
  EXPECT_TRUE(response.success);
  EXPECT_TRUE(response.message.empty());
  EXPECT_EQ(response.dofs.size(), 1u);
}

TEST(NodeBoundaries, TopicCallbackCatchesEveryException)
{
  EXPECT_EQ(guardCallback("joint_states", [] {}), "");
  EXPECT_EQ(guardCallback("joint_states", [] { throw drb::InvalidArgumentError("position[0]: not finite"); }),
            "position[0]: not finite");
  const std::string foreign = guardCallback("set_states", throwOutOfRange);
  EXPECT_EQ(foreign.rfind("internal error in set_states: ", 0), 0u) << foreign;
  EXPECT_NE(foreign.find("std::out_of_range"), std::string::npos) << foreign;
}

TEST(NodeBoundaries, StartUpReportsFailureInsteadOfAborting)
{
  EXPECT_TRUE(runAtStart("cannot load the scene", [] {}));
  EXPECT_FALSE(runAtStart("cannot load the scene", [] { throw drb::SceneDescriptionError("no body"); }));
  EXPECT_FALSE(runAtStart("cannot load the scene", throwOutOfRange));
  EXPECT_FALSE(runAtStart("cannot start", [] { throw std::runtime_error("state file unwritable"); }));
}
