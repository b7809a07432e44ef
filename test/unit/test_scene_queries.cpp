// Service logic on plain arrays: layouts, snapshots and the refusal of bad
// requests (each with a message naming the field, and no partial effect),
// for free bodies (articulated ones: test_articulated_plumbing.cpp).
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
#include "../support/kinematics_oracles.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;

namespace
{
constexpr double kRelativeTolerance = 1e-14;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Two bodies: "cube" (8 corners of a 0.2 m box, 2 kg) and "ball" (114-vertex sphere).
drb::SceneQueries twoBodyScene()
{
  drb_test::urdf::TwoBodies scene;
  scene.cube_rpy = "0.1 0.2 0.3";
  return drb::SceneQueries(drb::loadSceneFromUrdf(drb_test::urdf::twoBodies(scene)));
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
      const drb::BodyModel& body = queries.body(i == 0 ? 1 : 0);
      // Independent reference: T^T R I_b R^T T from the elementary rotations.
      const Eigen::Matrix3d expected =
          drb_test::refMassMatrix<double>(Eigen::Map<const drb::Vector6<double>>(q.data() + 6 * slot), body.mass(),
                                          body.segments[0].inertia.inertia)
              .topLeftCorner<3, 3>();
      const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> M(answer.mass_matrices.data() + 36 * slot);
      EXPECT_LE((M.topLeftCorner<3, 3>() - expected).norm(), kRelativeTolerance * 10 * expected.norm());
      EXPECT_EQ(M(3, 3), body.mass());
      EXPECT_EQ(M(5, 5), body.mass());
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
  nan_state.x[4] = kNaN;
  DRB_EXPECT_THROWS_MESSAGE((queries.applyStates(current, { big, nan_state })), drb::InvalidArgumentError,
                            "states[1].q (body 'ball')[4]: not finite");
  DRB_EXPECT_THROWS_MESSAGE((queries.applyStates(current, { big, { "ghost", {} } })), drb::InvalidArgumentError,
                            "states[1].name: unknown body 'ghost'");
  DRB_EXPECT_THROWS_MESSAGE((queries.applyStates(current, { big, big })), drb::InvalidArgumentError,
                            "appears more than once");
}

TEST(SceneQueries, RefusesBadRequests)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  std::vector<double> positions{ 42.0 }, jacobians{ 42.0 };
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "ghost", {}, {}, positions, jacobians)),
                            drb::InvalidArgumentError, "body: unknown body 'ghost' (bodies: cube, ball)");
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "cube", { 0, 8 }, {}, positions, jacobians)),
                            drb::InvalidArgumentError,
                            "vertices[1]: index 8 out of range for body 'cube' with 8 vertices");
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "cube", {}, { 0, 0, 0 }, positions, jacobians)),
                            drb::InvalidArgumentError, "q: expected 6 values");
  DRB_EXPECT_THROWS_MESSAGE(
      (queries.vertexJacobians(current, "cube", {}, { 0, kNaN, 0, 0, 0, 0 }, positions, jacobians)),
      drb::InvalidArgumentError, "q[1]: not finite");
  EXPECT_EQ(positions, std::vector<double>{ 42.0 });  // outputs untouched on refusal
  DRB_EXPECT_THROWS_MESSAGE((queries.backprop(current, "cube", { 1, 2 }, { 1, 2, 3 }, {})), drb::InvalidArgumentError,
                            "gradients: expected 3 per vertex = 6, got 3 values");
  DRB_EXPECT_THROWS_MESSAGE((queries.backprop(current, "cube", { 1 }, { 1, kNaN, 3 }, {})), drb::InvalidArgumentError,
                            "gradients[1]: not finite");
  DRB_EXPECT_THROWS_MESSAGE((queries.backprop(current, "cube", {}, std::vector<double>(24, 1e308), {})),
                            drb::InvalidArgumentError, "result gradient");
  DRB_EXPECT_THROWS_MESSAGE((queries.massMatrices(current, { "cube" }, std::vector<double>(7, 0.0), false)),
                            drb::InvalidArgumentError, "q: expected a multiple of 6 x 1 bodies");
  DRB_EXPECT_THROWS_MESSAGE((queries.massMatrices(current, { "cube", "nope" }, {}, false)), drb::InvalidArgumentError,
                            "bodies[1]: unknown body 'nope'");
  DRB_EXPECT_THROWS_MESSAGE((queries.getStates(current, { "nope" })), drb::InvalidArgumentError,
                            "bodies[0]: unknown body 'nope'");
  // Over the documented limit: refused from the sizes alone.
  DRB_EXPECT_THROWS_MESSAGE(
      (queries.massMatrices(current, { "cube" },
                            std::vector<double>(6 * (drb::RequestLimits::kMaxMassMatricesWithDerivatives + 1), 0.0),
                            true)),
      drb::InvalidArgumentError, "at most 100000 matrices");
}

// ~get_vertex_jacobians_compact: the positions and the rotation block (the
// first three columns of J) of the full answer, in double bit for bit and in
// float32 as the double values rounded once.
TEST(SceneQueries, CompactTransportIsTheFullAnswerReduced)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  const std::vector<std::uint32_t> vertices = { 7, 0, 3, 7 };
  const std::vector<double> q = { 0.4, -1.1, 2.5, -0.3, 0.2, 1.5 };
  std::vector<double> positions, jacobians;
  queries.vertexJacobians(current, "cube", vertices, q, positions, jacobians);

  std::vector<double> compact_positions, rotation;
  queries.vertexRotationJacobians(current, "cube", vertices, q, false, compact_positions, rotation);
  ASSERT_EQ(compact_positions.size(), 12u);
  ASSERT_EQ(rotation.size(), 36u);
  EXPECT_EQ(compact_positions, positions);
  std::vector<float> positions_f32, rotation_f32;
  queries.vertexRotationJacobians(current, "cube", vertices, q, false, positions_f32, rotation_f32);
  ASSERT_EQ(positions_f32.size(), 12u);
  ASSERT_EQ(rotation_f32.size(), 36u);
  for (std::size_t n = 0; n < vertices.size(); ++n)
    for (int r = 0; r < 3; ++r)
    {
      EXPECT_EQ(positions_f32[3 * n + r], static_cast<float>(positions[3 * n + r]));
      for (int c = 0; c < 3; ++c)
      {
        EXPECT_EQ(rotation[9 * n + 3 * r + c], jacobians[18 * n + 6 * r + c]);
        EXPECT_EQ(rotation_f32[9 * n + 3 * r + c], static_cast<float>(jacobians[18 * n + 6 * r + c]));
      }
    }
  // positions_only: the same positions, no rotation block.
  std::vector<double> only_positions, no_rotation{ 42.0 };
  queries.vertexRotationJacobians(current, "cube", vertices, q, true, only_positions, no_rotation);
  EXPECT_EQ(only_positions, positions);
  EXPECT_TRUE(no_rotation.empty());
}

// ~get_vertex_jacobians_compact fills the precision it is asked for and leaves
// the other pair of fields empty; its values are get_vertex_jacobians' (the
// rotation columns of a free body's Jacobian), rounded to float32 when asked.
TEST(SceneQueries, CompactServiceFillsTheAskedPrecisionOnly)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  const std::vector<std::uint32_t> vertices = { 5, 1 };
  const std::vector<double> q = { -0.7, 1.2, 0.3, 0.5, -0.4, 2.0, 0.1, -0.2, 0.9, 0.0, 0.3, -1.0 };  // K = 2
  std::vector<double> positions, jacobians;
  queries.vertexJacobians(current, "cube", vertices, q, positions, jacobians);
  ASSERT_EQ(positions.size(), 12u);
  ASSERT_EQ(jacobians.size(), 72u);

  drb::VertexJacobiansCompactAnswer full, single;
  queries.vertexJacobiansCompact(current, "cube", vertices, q, false, false, full);
  queries.vertexJacobiansCompact(current, "cube", vertices, q, false, true, single);
  EXPECT_TRUE(full.positions_f32.empty());
  EXPECT_TRUE(full.rotation_jacobians_f32.empty());
  EXPECT_TRUE(single.positions.empty());
  EXPECT_TRUE(single.rotation_jacobians.empty());
  ASSERT_EQ(full.positions.size(), 12u);
  ASSERT_EQ(full.rotation_jacobians.size(), 36u);
  ASSERT_EQ(single.positions_f32.size(), 12u);
  ASSERT_EQ(single.rotation_jacobians_f32.size(), 36u);
  for (std::size_t i = 0; i < positions.size(); ++i)
  {
    EXPECT_EQ(full.positions[i], positions[i]);
    EXPECT_EQ(single.positions_f32[i], static_cast<float>(positions[i]));
  }
  for (std::size_t row = 0; row < 12; ++row)  // K x N vertices x 3 rows, 3 rotation columns each
    for (std::size_t c = 0; c < 3; ++c)
    {
      EXPECT_EQ(full.rotation_jacobians[3 * row + c], jacobians[6 * row + c]);
      EXPECT_EQ(single.rotation_jacobians_f32[3 * row + c], static_cast<float>(jacobians[6 * row + c]));
    }
}

// Results that would not fit the output type are refused (naming q and the
// body) before anything is written, like get_vertex_jacobians: never inf.
// FLT_MAX = 3.4028e38, DBL_MAX = 1.7977e308.
TEST(SceneQueries, CompactTransportRefusesOverflow)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  // One floating body "b": a box of `size` [m] (vertices at +-size/2).
  const auto boxBody = [](const std::string& size) {
    using namespace drb_test::urdf;
    return drb::SceneQueries(
        drb::loadSceneFromUrdf(oneBody(inertial("1", diagonalInertia("1", "1", "1")) + collision(boxGeometry(size)))));
  };
  std::vector<float> positions_f32{ 42.0f }, rotation_f32{ 42.0f };
  std::vector<double> positions{ 42.0 }, rotation{ 42.0 };

  const drb::SceneQueries wide = boxBody("1e38 1 1"), wider = boxBody("1e39 1 1"), giant = boxBody("1e300 1 1");
  struct Overflow
  {
    const drb::SceneQueries& queries;
    std::string body;
    std::vector<double> q;
    bool single_precision;
    bool positions_only;
  };
  const Overflow overflows[] = {
    // float32: a translation beyond FLT_MAX (the 0.2 m cube), with and without the rotation block;
    { queries, "cube", { 0, 0, 0, 0, -3.5e38, 0 }, true, false },
    { queries, "cube", { 0, 0, 0, 0, -3.5e38, 0 }, true, true },
    // float32: vertices at 5e37 m and a translation of 3e38 m each fit, their sum does not;
    { wide, "b", { 0, 0, 0, 3e38, 0, 0 }, true, false },
    // float32: a body 1e39 m wide, so |p0| and |Jr| exceed FLT_MAX at q = 0;
    { wider, "b", { 0, 0, 0, 0, 0, 0 }, true, false },
    // double: a body 1e300 m wide at 1.7e308 m (the message of get_vertex_jacobians).
    { giant, "b", { 0, 0, 0, 1.7e308, 0, 0 }, false, false },
  };
  for (const Overflow& o : overflows)
  {
    const auto request = [&] {
      const drb::SceneState state = o.queries.initialState();
      if (o.single_precision)
        o.queries.vertexRotationJacobians(state, o.body, {}, o.q, o.positions_only, positions_f32, rotation_f32);
      else
        o.queries.vertexRotationJacobians(state, o.body, {}, o.q, o.positions_only, positions, rotation);
    };
    DRB_EXPECT_THROWS_MESSAGE(request(), drb::InvalidArgumentError,
                              "q: position too large: vertex positions of body '" + o.body + "' would overflow" +
                                  (o.single_precision ? " float32" : ""));
  }
  // Outputs untouched on refusal.
  EXPECT_EQ(positions_f32, std::vector<float>{ 42.0f });
  EXPECT_EQ(rotation_f32, std::vector<float>{ 42.0f });
  EXPECT_EQ(positions, std::vector<double>{ 42.0 });
  EXPECT_EQ(rotation, std::vector<double>{ 42.0 });

  // At the edge of the range: accepted, every value finite, as in
  // get_vertex_jacobians. The ball's vertices (|p0| = 0.1 m) vanish in the
  // rounding of a translation of FLT_MAX (float32) or DBL_MAX (double).
  const float flt_max = std::numeric_limits<float>::max();
  const double dbl_max = std::numeric_limits<double>::max();
  queries.vertexRotationJacobians(current, "ball", {}, { 0.3, 0.2, 0.1, flt_max, -flt_max, 0 }, false, positions_f32,
                                  rotation_f32);
  ASSERT_EQ(positions_f32.size(), 3u * 114u);
  EXPECT_EQ(positions_f32[0], flt_max);
  EXPECT_EQ(positions_f32[1], -flt_max);
  for (const std::vector<float>* field : { &positions_f32, &rotation_f32 })
    for (float value : *field)
      EXPECT_TRUE(std::isfinite(value));
  queries.vertexRotationJacobians(current, "ball", {}, { 0.3, 0.2, 0.1, 0, -dbl_max, dbl_max }, false, positions,
                                  rotation);
  EXPECT_EQ(positions[1], -dbl_max);
  EXPECT_EQ(positions[2], dbl_max);
  for (const std::vector<double>* field : { &positions, &rotation })
    for (double value : *field)
      EXPECT_TRUE(std::isfinite(value));
  std::vector<double> full_positions, full_jacobians;
  queries.vertexJacobians(current, "ball", {}, { 0.3, 0.2, 0.1, 0, -dbl_max, dbl_max }, full_positions,
                          full_jacobians);
  EXPECT_EQ(positions, full_positions);
  // The 1e38 m box at q = 0: vertices at 5e37 m, Jr entries up to 5e37 m.
  wide.vertexRotationJacobians(wide.initialState(), "b", {}, { 0, 0, 0, 0, 0, 0 }, false, positions_f32,
                               rotation_f32);
  for (const std::vector<float>* field : { &positions_f32, &rotation_f32 })
    for (float value : *field)
      EXPECT_TRUE(std::isfinite(value));
}
