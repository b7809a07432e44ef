// SceneQueries on articulated bodies (test/support/plumbing_scenes.h: cube,
// ball, arm of 9 dofs, crane of 2): state lengths, joint_states, and the
// layouts of every answer, each block compared bit for bit with a direct call
// of the core's algorithms (crba.h, mass_matrix_derivatives.h; their numbers
// are tested elsewhere). Free bodies: test_scene_queries.cpp.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "../support/body_models.h"
#include "../support/expect_throws.h"
#include "../support/plumbing_scenes.h"

namespace drb = diff_rigid_body;

namespace
{
const double kNaN = std::numeric_limits<double>::quiet_NaN();

template <typename T>
bool sameBits(const T* a, const T* b, std::size_t count)
{
  return count == 0 || std::memcmp(a, b, sizeof(T) * count) == 0;
}

std::vector<double> armAndCraneQ()
{
  return { 0.3, -0.4, 1.1, 0.5, -2.0, 0.25, 0.7, -1.2, 0.3, /* crane */ 2.5, -0.75 };
}
}  // namespace

TEST(ArticulatedPlumbing, StatesHaveEachBodysDofs)
{
  const drb::SceneQueries queries(drb_test::plumbing::scene());
  const drb::SceneState current = queries.initialState();
  ASSERT_EQ(current.size(), 4u);
  const std::size_t dofs[] = { 6, 6, 9, 2 };
  for (std::size_t i = 0; i < 4; ++i)
  {
    EXPECT_EQ(queries.dofs(i), dofs[i]) << "body " << i;
    EXPECT_EQ(static_cast<std::size_t>(current[i].size()), dofs[i]) << "body " << i;
  }
  const Eigen::VectorXd crane_x = (Eigen::VectorXd(2) << -0.0, 1e300).finished();
  const drb::SceneState next = queries.applyStates(current, { { "crane", crane_x } });
  EXPECT_TRUE(sameBits(next[3].data(), crane_x.data(), 2));
  EXPECT_EQ(queries.getStates(next, { "crane" })[0].x, crane_x);
  DRB_EXPECT_THROWS_MESSAGE((queries.applyStates(current, { { "crane", crane_x }, { "arm", Eigen::VectorXd::Zero(6) } })),
                            drb::InvalidArgumentError,
                            "states[1].q (body 'arm'): expected 9 values (the body's dofs), got 6 values");
  DRB_EXPECT_THROWS_MESSAGE((queries.applyStates(current, { { "cube", Eigen::VectorXd::Zero(9) } })),
                            drb::InvalidArgumentError,
                            "states[0].q (body 'cube'): expected 6 values (the body's dofs), got 9 values");
  Eigen::VectorXd arm_x = current[2];
  arm_x[8] = kNaN;
  DRB_EXPECT_THROWS_MESSAGE((queries.applyStates(current, { { "arm", arm_x } })), drb::InvalidArgumentError,
                            "states[0].q (body 'arm')[8]: not finite");
}

TEST(ArticulatedPlumbing, JointStatesSetIndependentJointsOnly)
{
  const drb::SceneQueries queries(drb_test::plumbing::scene());
  const drb::SceneState current = queries.initialState();
  std::vector<std::string> unknown{ "earlier" };
  const drb::SceneState next =
      queries.applyJointPositions(current, { "elbow", "boom_out", "finger_joint", "ghost", "shoulder", "elbow", "cube_joint" },
                                  { 0.5, -0.0, 9.0, 1.0, 1e-300, -2.5, 3.0 }, unknown);
  EXPECT_EQ(unknown, (std::vector<std::string>{ "earlier", "ghost", "cube_joint" }));
  EXPECT_EQ(next[2][6], 1e-300);  // shoulder: x index 6 (after the floating root's 6)
  EXPECT_EQ(next[2][7], -2.5);    // elbow, the later of two
  EXPECT_TRUE(std::signbit(next[3][1]));  // boom_out: x index 1 of the fixed-base crane
  for (std::size_t i : { 0u, 1u })
    EXPECT_TRUE(sameBits(next[i].data(), current[i].data(), 6)) << "free body " << i << " changed";
  EXPECT_TRUE(sameBits(next[2].data(), current[2].data(), 6)) << "the arm's root changed";
  EXPECT_EQ(next[2][8], current[2][8]) << "slide changed";  // the mimic finger_joint is ignored
  EXPECT_EQ(next[3][0], current[3][0]) << "mast_yaw changed";

  unknown.clear();
  DRB_EXPECT_THROWS_MESSAGE((queries.applyJointPositions(current, { "elbow", "ghost", "slide" }, { 0.1, kNaN, 0.2 },
                                                         unknown)),
                            drb::InvalidArgumentError, "position[1] (joint 'ghost'): not finite (nan)");
  DRB_EXPECT_THROWS_MESSAGE((queries.applyJointPositions(current, { "elbow", "slide" }, { 0.1 }, unknown)),
                            drb::InvalidArgumentError, "position: expected 2 values (one per name), got 1 values");
  EXPECT_TRUE(unknown.empty()) << "a dropped message listed unknown names";
}

TEST(ArticulatedPlumbing, MassMatricesLayoutAndDispatch)
{
  const drb::SceneQueries queries(drb_test::plumbing::scene());
  const drb::SceneState current = queries.initialState();
  const drb::BodyModel& arm = queries.body(2);
  const drb::BodyModel& crane = queries.body(3);
  using drb_test::core_body::massMatrixAt;
  using drb_test::core_body::massMatrixDerivativesAt;
  // K = 2 configurations of (crane, cube, arm): 2 + 6 + 9 = 17 values each.
  const std::vector<double> ac = armAndCraneQ();
  std::vector<double> q;
  for (int k = 0; k < 2; ++k)
  {
    q.insert(q.end(), { ac[9] + k, ac[10] - k });
    q.insert(q.end(), { 0.1 * k, 0.2, 0.3, 1.0, 2.0, 3.0 + k });
    for (int j = 0; j < 9; ++j)
      q.push_back(ac[j] - 0.1 * k);
  }
  const drb::MassMatrixAnswer answer = queries.massMatrices(current, { "crane", "cube", "arm" }, q, true);
  EXPECT_EQ(answer.dofs, (std::vector<std::uint32_t>{ 2, 6, 9 }));
  ASSERT_EQ(answer.mass_matrices.size(), 2u * (4 + 36 + 81));
  ASSERT_EQ(answer.derivatives.size(), 2u * (8 + 216 + 729));
  ASSERT_EQ(answer.cos_theta.size(), 6u);
  for (std::size_t k = 0; k < 2; ++k)
  {
    const double* qk = q.data() + 17 * k;
    const double* M = answer.mass_matrices.data() + 121 * k;
    const double* dM = answer.derivatives.data() + 953 * k;
    const std::string at = "configuration " + std::to_string(k);
    // crane: M (4 values) then dM (8), cos_theta 1.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> expected =
        massMatrixAt(crane, qk);
    EXPECT_TRUE(sameBits(M, expected.data(), 4)) << "crane M, " << at;
    std::vector<Eigen::MatrixXd> derivatives = massMatrixDerivativesAt(crane, qk);
    for (int j = 0; j < 2; ++j)
    {
      expected = derivatives[j];
      EXPECT_TRUE(sameBits(dM + 4 * j, expected.data(), 4)) << "crane dM/dx_" << j << ", " << at;
    }
    EXPECT_EQ(answer.cos_theta[3 * k], 1.0) << at;
    // cube: the bits of a request for it alone.
    const drb::MassMatrixAnswer cube =
        queries.massMatrices(current, { "cube" }, std::vector<double>(qk + 2, qk + 8), true);
    EXPECT_TRUE(sameBits(M + 4, cube.mass_matrices.data(), 36)) << "cube M, " << at;
    EXPECT_TRUE(sameBits(dM + 8, cube.derivatives.data(), 216)) << "cube dM, " << at;
    EXPECT_TRUE(sameBits(&answer.cos_theta[3 * k + 1], cube.cos_theta.data(), 1)) << at;
    // arm: M (81) and dM (729), cos_theta = cos(theta).
    expected = massMatrixAt(arm, qk + 8);
    EXPECT_TRUE(sameBits(M + 40, expected.data(), 81)) << "arm M, " << at;
    derivatives = massMatrixDerivativesAt(arm, qk + 8);
    for (int j = 0; j < 9; ++j)
    {
      expected = derivatives[j];
      EXPECT_TRUE(sameBits(dM + 224 + 81 * j, expected.data(), 81)) << "arm dM/dx_" << j << ", " << at;
    }
    EXPECT_EQ(answer.cos_theta[3 * k + 2], std::cos(qk[9])) << at;
  }
  // Empty q: the current state, every body.
  const drb::MassMatrixAnswer now = queries.massMatrices(current, {}, {}, false);
  EXPECT_EQ(now.dofs, (std::vector<std::uint32_t>{ 6, 6, 9, 2 }));
  EXPECT_EQ(now.mass_matrices.size(), 36u + 36u + 81u + 4u);
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> arm_now =
      massMatrixAt(arm, current[2].data());
  EXPECT_TRUE(sameBits(now.mass_matrices.data() + 72, arm_now.data(), 81));

  DRB_EXPECT_THROWS_MESSAGE((queries.massMatrices(current, { "crane", "cube", "arm" }, std::vector<double>(33, 0.0), false)),
                            drb::InvalidArgumentError,
                            "q: expected a multiple of 17 values (the sum of the 3 bodies' dofs), or empty for the "
                            "current state, got 33 values");
  // The budget of 25.2e6 doubles with derivatives: 31112 configurations of the arm (810 each) are over it.
  DRB_EXPECT_THROWS_MESSAGE((queries.massMatrices(current, { "arm" }, std::vector<double>(9 * 31112, 0.0), true)),
                            drb::InvalidArgumentError,
                            "q: expected at most 25200000 answer values (configurations x the sum over the 1 bodies "
                            "of dof^2 + dof^3), got 31112 x 810");
}
