// Service logic on plain arrays: layouts, snapshots and the refusal of bad
// requests (each with a message naming the field, and no partial effect).
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/scene_queries.h"

namespace drb = diff_rigid_body;

namespace
{
constexpr double kRelativeTolerance = 1e-14;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Two bodies: "cube" (8 corners of a 0.2 m box, 2 kg) and "ball" (114-vertex sphere).
drb::SceneQueries twoBodyScene()
{
  const std::string xml =
      "<robot name=\"r\"><link name=\"world\"/>"
      "<link name=\"cube\"><inertial><mass value=\"2\"/><inertia ixx=\"0.1\" iyy=\"0.2\" izz=\"0.25\" ixy=\"0.01\" "
      "ixz=\"0.02\" iyz=\"-0.03\"/></inertial><collision><geometry><box size=\"0.2 0.2 0.2\"/></geometry>"
      "</collision></link>"
      "<link name=\"ball\"><inertial><mass value=\"1\"/><inertia ixx=\"0.004\" iyy=\"0.004\" izz=\"0.004\" ixy=\"0\" "
      "ixz=\"0\" iyz=\"0\"/></inertial><collision><geometry><sphere radius=\"0.1\"/></geometry></collision></link>"
      "<joint name=\"jc\" type=\"floating\"><parent link=\"world\"/><child link=\"cube\"/>"
      "<origin xyz=\"0 0 1\" rpy=\"0.1 0.2 0.3\"/></joint>"
      "<joint name=\"jb\" type=\"floating\"><parent link=\"world\"/><child link=\"ball\"/>"
      "<origin xyz=\"1 0 1\"/></joint></robot>";
  return drb::SceneQueries(drb::loadSceneFromUrdf(xml));
}

// Independent reference: T^T R I_b R^T T from the elementary rotations.
Eigen::Matrix3d angularBlockReference(const Eigen::Matrix3d& inertia, double phi, double theta, double psi)
{
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  Eigen::Matrix3d T;
  T.col(0) = R.col(0);  // X'' axis
  T.col(1) = Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d::UnitY();  // Y' axis
  T.col(2) = Eigen::Vector3d::UnitZ();
  return T.transpose() * R * inertia * R.transpose() * T;
}

template <typename Call>
void expectRejected(Call call, const std::string& fragment)
{
  try
  {
    call();
    FAIL() << "accepted, expected an error containing '" << fragment << "'";
  }
  catch (const drb::InvalidArgumentError& e)
  {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(SceneQueries, BatchedMassMatrixLayout)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  // K = 3 configurations of the bodies (ball, cube): matrix (k n + i) at (k n + i) 36.
  std::vector<double> q;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 2; ++i)
      for (double v : { 0.3 * k - 0.2 * i, 1.5 - 0.7 * k, 0.1 * k, 1.0, 2.0, 3.0 })
        q.push_back(v);
  const drb::MassMatrixAnswer answer = queries.massMatrices(current, { "ball", "cube" }, q, true);
  ASSERT_EQ(answer.bodies, (std::vector<std::string>{ "ball", "cube" }));
  ASSERT_EQ(answer.mass_matrices.size(), 6u * 36u);
  ASSERT_EQ(answer.derivatives.size(), 6u * 216u);
  ASSERT_EQ(answer.cos_theta.size(), 6u);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 2; ++i)
    {
      const std::size_t slot = 2 * k + i;
      const drb::RigidBody& body = queries.body(i == 0 ? 1 : 0);
      const Eigen::Matrix3d expected =
          angularBlockReference(body.inertia_body, q[6 * slot], q[6 * slot + 1], q[6 * slot + 2]);
      const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> M(answer.mass_matrices.data() + 36 * slot);
      EXPECT_LE((M.topLeftCorner<3, 3>() - expected).norm(), kRelativeTolerance * 10 * expected.norm());
      EXPECT_EQ(M(3, 3), body.mass);
      EXPECT_EQ(M(5, 5), body.mass);
      EXPECT_EQ(M(0, 4), 0.0);
      EXPECT_NEAR(answer.cos_theta[slot], std::cos(q[6 * slot + 1]), 1e-16);
      // dM/dpsi and dM/dt are exactly zero.
      for (int j = 2; j < 6; ++j)
        for (int e = 0; e < 36; ++e)
          EXPECT_EQ(answer.derivatives[216 * slot + 36 * j + e], 0.0);
    }
  // Empty q evaluates the current state; empty bodies means all, in scene order.
  const drb::MassMatrixAnswer now = queries.massMatrices(current, {}, {}, false);
  EXPECT_EQ(now.bodies, (std::vector<std::string>{ "cube", "ball" }));
  EXPECT_EQ(now.mass_matrices.size(), 72u);
  EXPECT_TRUE(now.derivatives.empty());
  EXPECT_NEAR(now.cos_theta[0], std::cos(0.2), 1e-15);
}

TEST(SceneQueries, VertexJacobiansAndBackpropAgree)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  std::vector<double> positions, jacobians;
  queries.vertexJacobians(current, "cube", { 7, 0, 7 }, {}, positions, jacobians);
  ASSERT_EQ(positions.size(), 9u);
  ASSERT_EQ(jacobians.size(), 54u);
  // The repeated vertex gives identical rows.
  for (int e = 0; e < 18; ++e)
    EXPECT_EQ(jacobians[e], jacobians[36 + e]);
  // Backprop equals J^T g summed, with J from the Jacobian answer.
  const std::vector<double> g = { 0.1, -0.2, 0.3, 1.0, 0.5, -0.5, 0.1, -0.2, 0.3 };
  const drb::Vector6<double> gradient = queries.backprop(current, "cube", { 7, 0, 7 }, g, {});
  drb::Vector6<double> expected = drb::Vector6<double>::Zero();
  for (int n = 0; n < 3; ++n)
    expected += Eigen::Map<const Eigen::Matrix<double, 3, 6, Eigen::RowMajor>>(jacobians.data() + 18 * n)
                    .transpose() *
                Eigen::Map<const Eigen::Vector3d>(g.data() + 3 * n);
  EXPECT_LE((gradient - expected).norm(), kRelativeTolerance * 10 * expected.norm());
}

TEST(SceneQueries, SetStateIsAllOrNothingAndBitExact)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  drb::NamedState big{ "cube", (drb::Vector6<double>() << 1e6, -4.0, 7.5, 0, 0, 0).finished() };
  const drb::SceneState next = queries.applyStates(current, { big });
  EXPECT_EQ(next[0][0], 1e6);  // no wrapping
  EXPECT_EQ(next[1], current[1]);

  drb::NamedState nan_state{ "ball", drb::Vector6<double>::Zero() };
  nan_state.q[4] = kNaN;
  expectRejected([&] { queries.applyStates(current, { big, nan_state }); }, "states[1].q (body 'ball')[4]: not finite");
  expectRejected([&] { queries.applyStates(current, { big, { "ghost", {} } }); }, "states[1].name: unknown body 'ghost'");
  expectRejected([&] { queries.applyStates(current, { big, big }); }, "appears more than once");
}

TEST(SceneQueries, RefusesBadRequests)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  std::vector<double> positions{ 42.0 }, jacobians{ 42.0 };
  expectRejected([&] { queries.vertexJacobians(current, "ghost", {}, {}, positions, jacobians); },
                 "body: unknown body 'ghost' (bodies: cube, ball)");
  expectRejected([&] { queries.vertexJacobians(current, "cube", { 0, 8 }, {}, positions, jacobians); },
                 "vertices[1]: index 8 out of range for body 'cube' with 8 vertices");
  expectRejected([&] { queries.vertexJacobians(current, "cube", {}, { 0, 0, 0 }, positions, jacobians); },
                 "q: expected 6 values");
  expectRejected([&] { queries.vertexJacobians(current, "cube", {}, { 0, kNaN, 0, 0, 0, 0 }, positions, jacobians); },
                 "q[1]: not finite");
  EXPECT_EQ(positions, std::vector<double>{ 42.0 });  // outputs untouched on refusal
  expectRejected([&] { queries.backprop(current, "cube", { 1, 2 }, { 1, 2, 3 }, {}); },
                 "gradients: expected 3 per vertex = 6, got 3 values");
  expectRejected([&] { queries.backprop(current, "cube", { 1 }, { 1, kNaN, 3 }, {}); }, "gradients[1]: not finite");
  expectRejected([&] { queries.backprop(current, "cube", {}, std::vector<double>(24, 1e308), {}); },
                 "result gradient");
  expectRejected([&] { queries.massMatrices(current, { "cube" }, std::vector<double>(7, 0.0), false); },
                 "q: expected a multiple of 6 x 1 bodies");
  expectRejected([&] { queries.massMatrices(current, { "cube", "nope" }, {}, false); },
                 "bodies[1]: unknown body 'nope'");
  expectRejected([&] { queries.getStates(current, { "nope" }); }, "bodies[0]: unknown body 'nope'");
  // Over the documented limit: refused from the sizes alone.
  expectRejected(
      [&] {
        queries.massMatrices(current, { "cube" },
                             std::vector<double>(6 * (drb::RequestLimits::kMaxMassMatricesWithDerivatives + 1), 0.0),
                             true);
      },
      "at most 100000 matrices");
}
