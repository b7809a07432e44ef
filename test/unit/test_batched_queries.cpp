// K configurations of one body in one request (get_vertex_jacobians, its
// compact transport and backprop): each configuration's block of the answer
// has the same bits as a request with that configuration alone, and sizes
// that do not fit K are refused, naming the field, before anything is written.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/algorithm/free_body/vertex_jacobian.h"  // kStreamingStoreBytes
#include "diff_rigid_body/services/scene_queries.h"
#include "../support/body_models.h"
#include "../support/expect_throws.h"
#include "../support/plumbing_scenes.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;

namespace
{
const double kHalfPi = 1.5707963267948966;

// "cube" (8 corners, its initial state at rpy 0.1 0.2 0.3) and "ball" (114 vertices).
drb::SceneQueries twoBodyScene()
{
  drb_test::urdf::TwoBodies scene;
  scene.cube_rpy = "0.1 0.2 0.3";
  return drb::SceneQueries(drb::loadSceneFromUrdf(drb_test::urdf::twoBodies(scene)));
}

// One body "cloud" of `count` pseudo-random vertices within 1 m of its COM.
drb::SceneQueries cloudScene(std::size_t count)
{
  drb::Scene scene;
  scene.fixed_frame = "world";
  Eigen::Matrix3Xd vertices(3, static_cast<Eigen::Index>(count));
  std::uint64_t state = 12345;
  for (Eigen::Index i = 0; i < vertices.size(); ++i)
  {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    vertices.data()[i] = static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
  }
  scene.bodies.push_back(drb_test::core_body::freeObject("cloud", 1.0, Eigen::Matrix3d::Zero(), vertices));
  return drb::SceneQueries(std::move(scene));
}

// K configurations: generic ones, exact gimbal lock (theta = +-pi/2), one ulp
// from it, large angles and large translations.
std::vector<double> configurations(std::size_t K)
{
  const double table[][6] = {
    { 0.3, -0.4, 1.1, 0.5, -2.0, 0.25 },
    { 0.7, kHalfPi, -0.2, 1.0, 2.0, 3.0 },
    { -1.2, std::nextafter(kHalfPi, 0.0), 2.5, -1e3, 0.0, 7.0 },
    { 2.9, -kHalfPi, 0.4, 0.0, 0.0, 0.0 },
    { 1e6, std::nextafter(-kHalfPi, 0.0), -3e5, 1e8, -1e8, 5e7 },
    { 0.0, 0.0, 0.0, -0.5, 0.5, -0.5 },
    { -0.9, 1.2, 3.1, 4.0, -4.0, 1e-300 },
  };
  std::vector<double> q;
  for (std::size_t k = 0; k < K; ++k)
    q.insert(q.end(), table[k % 7], table[k % 7] + 6);
  return q;
}

std::vector<double> slice(const std::vector<double>& values, std::size_t first, std::size_t count)
{
  return std::vector<double>(values.begin() + first, values.begin() + first + count);
}

// Pseudo-random gradients dL/dp, of both signs and mixed magnitudes.
std::vector<double> someGradients(std::size_t count)
{
  std::vector<double> g(count);
  for (std::size_t i = 0; i < count; ++i)
    g[i] = std::sin(0.7 * static_cast<double>(i) + 0.3) * std::pow(10.0, static_cast<double>(i % 5) - 2.0);
  return g;
}

// Bitwise equality of `count` values (so 0.0 and -0.0 differ, and NaN payloads count).
template <typename T>
void expectSameBits(const T* batched, const T* single, std::size_t count, const std::string& what)
{
  for (std::size_t i = 0; i < count; ++i)
    if (std::memcmp(batched + i, single + i, sizeof(T)) != 0)
    {
      ADD_FAILURE() << what << ": value " << i << " differs: batched " << batched[i] << ", single " << single[i];
      return;
    }
}

std::size_t selected(const drb::SceneQueries& queries, const std::string& body,
                     const std::vector<std::uint32_t>& vertices)
{
  const std::size_t index = queries.bodyIndex(body, "body");
  return vertices.empty() ? queries.scene().bodies[index].vertexCount() : vertices.size();
}

// Every answer of a K-configuration request equals the K single requests, bit for bit.
void expectBatchedEqualsSingles(const drb::SceneQueries& queries, const std::string& body,
                                const std::vector<std::uint32_t>& vertices, std::size_t K)
{
  const drb::SceneState current = queries.initialState();
  const std::vector<double> q = configurations(K);
  const std::size_t N = selected(queries, body, vertices);
  const std::string where = body + ", K = " + std::to_string(K) + ", N = " + std::to_string(N);

  std::vector<double> P, J;
  queries.vertexJacobians(current, body, vertices, q, P, J);
  ASSERT_EQ(P.size(), K * N * 3) << where;
  ASSERT_EQ(J.size(), K * N * 18) << where;
  std::vector<double> Pr, Jr;
  queries.vertexRotationJacobians<double>(current, body, vertices, q, false, Pr, Jr);
  ASSERT_EQ(Jr.size(), K * N * 9) << where;
  std::vector<float> Pf, Jf, Pf_only, none;
  queries.vertexRotationJacobians<float>(current, body, vertices, q, false, Pf, Jf);
  queries.vertexRotationJacobians<float>(current, body, vertices, q, true, Pf_only, none);
  EXPECT_TRUE(none.empty()) << where;
  const std::vector<double> g = someGradients(K * N * 3);
  const std::vector<double> dL_dq = queries.backpropConfigurations(current, body, vertices, g, q);
  ASSERT_EQ(dL_dq.size(), K * 6) << where;

  for (std::size_t k = 0; k < K; ++k)
  {
    const std::vector<double> qk = slice(q, 6 * k, 6);
    const std::string at = where + ", configuration " + std::to_string(k);
    std::vector<double> p1, j1, pr1, jr1;
    std::vector<float> pf1, jf1, pfo1, nonef;
    queries.vertexJacobians(current, body, vertices, qk, p1, j1);
    expectSameBits(P.data() + 3 * N * k, p1.data(), 3 * N, "positions, " + at);
    expectSameBits(J.data() + 18 * N * k, j1.data(), 18 * N, "jacobians, " + at);
    queries.vertexRotationJacobians<double>(current, body, vertices, qk, false, pr1, jr1);
    expectSameBits(Pr.data() + 3 * N * k, pr1.data(), 3 * N, "compact positions, " + at);
    expectSameBits(Jr.data() + 9 * N * k, jr1.data(), 9 * N, "compact rotation_jacobians, " + at);
    queries.vertexRotationJacobians<float>(current, body, vertices, qk, false, pf1, jf1);
    expectSameBits(Pf.data() + 3 * N * k, pf1.data(), 3 * N, "positions_f32, " + at);
    expectSameBits(Jf.data() + 9 * N * k, jf1.data(), 9 * N, "rotation_jacobians_f32, " + at);
    queries.vertexRotationJacobians<float>(current, body, vertices, qk, true, pfo1, nonef);
    expectSameBits(Pf_only.data() + 3 * N * k, pfo1.data(), 3 * N, "positions_only f32, " + at);
    const drb::Vector6<double> single = queries.backprop(current, body, vertices, slice(g, 3 * N * k, 3 * N), qk);
    expectSameBits(dL_dq.data() + 6 * k, single.data(), 6, "backprop gradient, " + at);
  }
}
}  // namespace

TEST(BatchedQueries, EqualSingleRequestsBitForBit)
{
  const drb::SceneQueries queries = twoBodyScene();
  const std::vector<std::vector<std::uint32_t>> subsets = { {}, { 5 }, { 7, 0, 7, 3 }, { 113, 0, 57, 2, 2 } };
  for (std::size_t K : { 1u, 2u, 7u })
  {
    for (const std::vector<std::uint32_t>& vertices : subsets)
    {
      const std::string body = vertices.size() == 5 ? "ball" : "cube";
      expectBatchedEqualsSingles(queries, body, vertices, K);
    }
    expectBatchedEqualsSingles(queries, "ball", {}, K);
  }
}

TEST(BatchedQueries, StreamingStoresOfASingleRequestGiveTheSameBits)
{
  // 116509 vertices: a single request's J takes 16 MiB + 72 B, so it is
  // written with streaming stores (kStreamingStoreBytes), while configuration
  // 1's block starts 8 bytes off a 16-byte boundary and takes ordinary stores.
  const drb::SceneQueries queries = cloudScene(116509);
  ASSERT_GE(18 * sizeof(double) * 116509, drb::kStreamingStoreBytes);
  expectBatchedEqualsSingles(queries, "cloud", {}, 2);
}

TEST(BatchedQueries, EmptyQIsOneConfigurationAtTheCurrentState)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  std::vector<double> now_p, now_j, at_p, at_j;
  queries.vertexJacobians(current, "cube", {}, {}, now_p, now_j);
  queries.vertexJacobians(current, "cube", {}, std::vector<double>(current[0].data(), current[0].data() + 6), at_p,
                          at_j);
  ASSERT_EQ(now_p.size(), 24u);
  expectSameBits(now_p.data(), at_p.data(), 24, "positions at the current state");
  expectSameBits(now_j.data(), at_j.data(), 144, "jacobians at the current state");
  EXPECT_EQ(queries.backpropConfigurations(current, "cube", {}, someGradients(24), {}).size(), 6u);
}

TEST(BatchedQueries, RefusesSizesThatDoNotFitKConfigurations)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  std::vector<double> positions{ 42.0 }, jacobians{ 43.0 };
  std::vector<float> positions_f32{ 44.0f }, rotation_f32{ 45.0f };
  // q of 6 K + 1 values.
  const std::vector<double> q13(13, 0.0);
  const char* kQSize =
      "q: expected 6 values per configuration (6 K for K configurations, or empty for the current state), got 13 "
      "values";
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "cube", {}, q13, positions, jacobians)),
                            drb::InvalidArgumentError, kQSize);
  DRB_EXPECT_THROWS_MESSAGE(
      (queries.vertexRotationJacobians<float>(current, "cube", {}, q13, false, positions_f32, rotation_f32)),
      drb::InvalidArgumentError, kQSize);
  DRB_EXPECT_THROWS_MESSAGE((queries.backpropConfigurations(current, "cube", { 0 }, std::vector<double>(6, 1.0), q13)),
                            drb::InvalidArgumentError, kQSize);
  // Gradients for K = 1 with q for K = 2 (and one value short).
  const std::vector<double> q12 = configurations(2);
  DRB_EXPECT_THROWS_MESSAGE((queries.backpropConfigurations(current, "cube", { 1, 2 }, someGradients(6), q12)),
                            drb::InvalidArgumentError,
                            "gradients: expected 3 per vertex and configuration = 3 x 2 vertices x 2 configurations "
                            "= 12, got 6 values");
  DRB_EXPECT_THROWS_MESSAGE((queries.backpropConfigurations(current, "cube", { 1, 2 }, someGradients(11), q12)),
                            drb::InvalidArgumentError, "= 12, got 11 values");
  // The single-configuration entry point refuses K > 1 with its own message.
  DRB_EXPECT_THROWS_MESSAGE((queries.backprop(current, "cube", { 1, 2 }, someGradients(12), q12)),
                            drb::InvalidArgumentError, "q: expected 6 values (or empty for the current state), got 12");
  // K x N over the vertex limit: ball has 114 vertices.
  const std::size_t K = drb::RequestLimits::kMaxVertices / 114 + 1;
  const std::vector<double> many(6 * K, 0.0);
  const std::string over = "q, vertices: expected at most 4194304 vertices over all configurations (configurations x "
                           "vertices), got " +
                           std::to_string(K) + " x 114";
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "ball", {}, many, positions, jacobians)),
                            drb::InvalidArgumentError, over);
  DRB_EXPECT_THROWS_MESSAGE(
      (queries.vertexRotationJacobians<float>(current, "ball", {}, many, true, positions_f32, rotation_f32)),
      drb::InvalidArgumentError, over);
  DRB_EXPECT_THROWS_MESSAGE((queries.backpropConfigurations(current, "ball", {}, {}, many)),
                            drb::InvalidArgumentError, over);
  // K - 1 configurations of all 114 vertices fit (K - 1 = floor(2^22 / 114)): the next check, on the gradients, refuses.
  DRB_EXPECT_THROWS_MESSAGE((queries.backpropConfigurations(current, "ball", {}, {}, slice(many, 0, 6 * (K - 1)))),
                            drb::InvalidArgumentError, "gradients: expected 3 per vertex and configuration");
  EXPECT_EQ(positions, std::vector<double>{ 42.0 });
  EXPECT_EQ(jacobians, std::vector<double>{ 43.0 });
  EXPECT_EQ(positions_f32, std::vector<float>{ 44.0f });
  EXPECT_EQ(rotation_f32, std::vector<float>{ 45.0f });
}

TEST(BatchedQueries, RefusalsNameTheConfigurationOrTheValue)
{
  const drb::SceneQueries queries = twoBodyScene();
  const drb::SceneState current = queries.initialState();
  std::vector<double> positions{ 42.0 }, jacobians{ 43.0 };
  std::vector<double> q = configurations(3);
  q[13] = std::numeric_limits<double>::quiet_NaN();  // configuration 2, theta
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "cube", {}, q, positions, jacobians)),
                            drb::InvalidArgumentError, "q[13]: not finite");
  // A body 1e300 m wide (its vertex radius overflows to inf, so every
  // configuration would): the first configuration is named.
  const drb::SceneQueries giant(drb::loadSceneFromUrdf(
      drb_test::urdf::oneBody(drb_test::urdf::inertial() + drb_test::urdf::collision("<box size=\"1e300 1 1\"/>"))));
  const std::vector<double> far = { 0, 0, 0, 1.0, 0, 0, 0, 0, 0, 1.7e308, 0, 0 };
  DRB_EXPECT_THROWS_MESSAGE(
      (giant.vertexJacobians(giant.initialState(), "b", {}, far, positions, jacobians)), drb::InvalidArgumentError,
      "q (configuration 0): position too large: vertex positions of body 'b' would overflow");
  std::vector<float> positions_f32{ 44.0f }, rotation_f32{ 45.0f };
  const std::vector<double> beyond_float = { 0, 0, 0, 1.0, 0, 0, 0, 0, 0, 0, 0, -3.5e38, 0, 0, 0, 0, 0, 0 };
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexRotationJacobians<float>(current, "cube", {}, beyond_float, false,
                                                                    positions_f32, rotation_f32)),
                            drb::InvalidArgumentError,
                            "q (configuration 1): position too large: vertex positions of body 'cube' would overflow "
                            "float32");
  EXPECT_EQ(positions, std::vector<double>{ 42.0 });
  EXPECT_EQ(jacobians, std::vector<double>{ 43.0 });
  EXPECT_EQ(positions_f32, std::vector<float>{ 44.0f });
  // Backprop: a non-finite gradient of configuration 1 is named by its index in `gradients`.
  std::vector<double> g = someGradients(2 * 2 * 3);
  g[8] = -std::numeric_limits<double>::infinity();
  DRB_EXPECT_THROWS_MESSAGE((queries.backpropConfigurations(current, "cube", { 1, 2 }, g, configurations(2))),
                            drb::InvalidArgumentError, "gradients[8]: not finite (-inf)");
  // Finite gradients whose sum overflows in configuration 1 only: the index is in the K x 6 answer.
  std::vector<double> huge = someGradients(8 * 3);
  huge.insert(huge.end(), 8 * 3, 1e308);
  const std::string message = DRB_EXPECT_THROWS_MESSAGE(
      (queries.backpropConfigurations(current, "cube", {}, huge, configurations(2))), drb::InvalidArgumentError,
      "result gradient (the gradients are too large)[");
  const std::size_t at = message.find(")[");
  ASSERT_NE(at, std::string::npos);
  EXPECT_GE(std::stoul(message.substr(at + 2)), 6u) << message;
}

// ---------------------------------------------------------------------------
// Articulated bodies (plumbing_scenes.h): K configurations of d values; each
// block is the bits of the direct call (vertex_jacobians.h, vertex_backprop.h)
// and of its single request.
namespace
{
/// K configurations of body `index`: a floating root's 6 from the table, then joint values.
std::vector<double> articulatedConfigurations(const drb::SceneQueries& queries, std::size_t index, std::size_t K)
{
  const drb::BodyModel& body = queries.body(index);
  const std::vector<double> roots = configurations(K);
  std::vector<double> q;
  for (std::size_t k = 0; k < K; ++k)
  {
    if (body.hasFreeRoot())
      q.insert(q.end(), roots.begin() + 6 * k, roots.begin() + 6 * k + 6);
    for (std::size_t j = 0; j < body.joint_names.size(); ++j)
      q.push_back(std::sin(1.3 * static_cast<double>(k) + static_cast<double>(j)) * (k == 4 ? 1e6 : 1.0));
  }
  return q;
}

void expectArticulatedBlocks(const drb::SceneQueries& queries, const std::string& name,
                             const std::vector<std::uint32_t>& vertices, std::size_t K)
{
  const drb::SceneState current = queries.initialState();
  const std::size_t index = queries.bodyIndex(name, "body");
  const drb::BodyModel& body = queries.body(index);
  const std::size_t d = body.coordinates, N = selected(queries, name, vertices), w = queries.compactColumns(index);
  const std::vector<double> q = articulatedConfigurations(queries, index, K);
  const std::string where = name + ", K = " + std::to_string(K) + ", N = " + std::to_string(N);

  std::vector<double> P, J, Pr, Jr;
  std::vector<float> Pf, Jf, Po, none{ 1.0f };
  queries.vertexJacobians(current, name, vertices, q, P, J);
  queries.vertexRotationJacobians<double>(current, name, vertices, q, false, Pr, Jr);
  queries.vertexRotationJacobians<float>(current, name, vertices, q, false, Pf, Jf);
  queries.vertexRotationJacobians<float>(current, name, vertices, q, true, Po, none);
  ASSERT_EQ(P.size(), 3 * N * K) << where;
  ASSERT_EQ(J.size(), 3 * d * N * K) << where;
  ASSERT_EQ(Jr.size(), 3 * w * N * K) << where;
  EXPECT_TRUE(none.empty()) << where;
  expectSameBits(Pr.data(), P.data(), P.size(), "compact positions, " + where);
  expectSameBits(Po.data(), Pf.data(), Pf.size(), "positions_only f32, " + where);
  const std::vector<double> g = someGradients(3 * N * K);
  const std::vector<double> dL = queries.backpropConfigurations(current, name, vertices, g, q);
  ASSERT_EQ(dL.size(), d * K) << where;
  // The compact columns: all but x[3..5] with a floating root, else all.
  std::vector<std::size_t> columns;
  for (std::size_t c = 0; c < d; ++c)
    if (!body.hasFreeRoot() || c < 3 || c > 5)
      columns.push_back(c);
  ASSERT_EQ(columns.size(), w) << where;

  for (std::size_t k = 0; k < K; ++k)
  {
    const std::string at = where + ", configuration " + std::to_string(k);
    const std::vector<double> qk = slice(q, d * k, d);
    std::vector<double> p0(3 * N), j0(3 * d * N), dL0(d);
    drb_test::core_body::vertexJacobiansAt(body, false, vertices, qk.data(), p0.data(), j0.data());
    drb_test::core_body::backpropAt(body, vertices, g.data() + 3 * N * k, qk.data(), dL0.data());
    expectSameBits(P.data() + 3 * N * k, p0.data(), 3 * N, "positions vs vertexJacobians, " + at);
    expectSameBits(J.data() + 3 * d * N * k, j0.data(), 3 * d * N, "jacobians vs vertexJacobians, " + at);
    expectSameBits(dL.data() + d * k, dL0.data(), d, "backprop vs vertexBackprop, " + at);
    for (std::size_t n = 0; n < N; ++n)
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < w; ++c)
        {
          const double full = J[3 * d * N * k + 3 * d * n + d * r + columns[c]];
          const std::size_t at_compact = 3 * w * N * k + 3 * w * n + w * r + c;
          expectSameBits(&Jr[at_compact], &full, 1, "compact J column " + std::to_string(columns[c]) + ", " + at);
          const float rounded = static_cast<float>(full);
          expectSameBits(&Jf[at_compact], &rounded, 1, "compact f32 J, " + at);
        }
    std::vector<double> p1, j1;
    queries.vertexJacobians(current, name, vertices, qk, p1, j1);
    expectSameBits(P.data() + 3 * N * k, p1.data(), 3 * N, "positions vs single request, " + at);
    expectSameBits(J.data() + 3 * d * N * k, j1.data(), 3 * d * N, "jacobians vs single request, " + at);
    const Eigen::VectorXd single = queries.backprop(current, name, vertices, slice(g, 3 * N * k, 3 * N), qk);
    ASSERT_EQ(static_cast<std::size_t>(single.size()), d) << at;
    expectSameBits(dL.data() + d * k, single.data(), d, "backprop vs single request, " + at);
  }
}
}  // namespace

TEST(BatchedQueries, ArticulatedBlocksAreTheDirectCallsBitForBit)
{
  const drb::SceneQueries queries(drb_test::plumbing::scene());
  for (std::size_t K : { 1u, 2u, 7u })
    for (const char* body : { "arm", "crane" })
    {
      expectArticulatedBlocks(queries, body, {}, K);
      expectArticulatedBlocks(queries, body, { 4, 0, 4, 2 }, K);
    }
  expectArticulatedBlocks(queries, "arm", { 13, 12, 3, 7 }, 2);  // the finger (mimic) and the slider
  // The current state when q is empty.
  const drb::SceneState current = queries.initialState();
  std::vector<double> now_p, now_j, at_p, at_j;
  queries.vertexJacobians(current, "arm", {}, {}, now_p, now_j);
  queries.vertexJacobians(current, "arm", {}, std::vector<double>(current[2].data(), current[2].data() + 9), at_p,
                          at_j);
  ASSERT_EQ(now_j.size(), 14u * 27u);
  expectSameBits(now_j.data(), at_j.data(), now_j.size(), "arm jacobians at the current state");
}

TEST(BatchedQueries, ArticulatedRefusals)
{
  const drb::SceneQueries queries(drb_test::plumbing::scene());
  const drb::SceneState current = queries.initialState();
  std::vector<double> positions{ 42.0 }, jacobians{ 43.0 };
  std::vector<float> positions_f32{ 44.0f }, jacobians_f32{ 45.0f };
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "arm", {}, std::vector<double>(10, 0.0), positions,
                                                     jacobians)),
                            drb::InvalidArgumentError,
                            "q: expected 9 values per configuration (9 K for K configurations, or empty for the "
                            "current state), got 10 values");
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "crane", { 1, 5 }, {}, positions, jacobians)),
                            drb::InvalidArgumentError,
                            "vertices[1]: index 5 out of range for body 'crane' with 5 vertices");
  DRB_EXPECT_THROWS_MESSAGE((queries.backprop(current, "crane", { 1 }, { 1, 2, 3 }, std::vector<double>(6, 0.0))),
                            drb::InvalidArgumentError, "q: expected 2 values (or empty for the current state), got 6");
  // The slide (axis (1, 1, 0)/sqrt 2) at 1.7e308 with the root at x = 1.7e308:
  // the slider's frame overflows in configuration 1.
  std::vector<double> q = articulatedConfigurations(queries, 2, 2);
  q[9 + 3] = 1.7e308;
  q[9 + 8] = 1.7e308;
  const char* kOverflow = "q (configuration 1): position too large: vertex positions of body 'arm' would overflow";
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexJacobians(current, "arm", {}, q, positions, jacobians)),
                            drb::InvalidArgumentError, kOverflow);
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexRotationJacobians<double>(current, "arm", { 0 }, q, true, positions,
                                                                     jacobians)),
                            drb::InvalidArgumentError, kOverflow);
  DRB_EXPECT_THROWS_MESSAGE((queries.backpropConfigurations(current, "arm", { 0 }, std::vector<double>(6, 1.0), q)),
                            drb::InvalidArgumentError, kOverflow);
  // The boom out at 3.5e38 m along x: finite in double, beyond float32.
  const std::vector<double> far = { 0.0, 3.5e38 };
  queries.vertexJacobians(current, "crane", {}, far, positions, jacobians);
  for (double value : positions)
    EXPECT_TRUE(std::isfinite(value));
  positions = { 42.0 };
  jacobians = { 43.0 };
  DRB_EXPECT_THROWS_MESSAGE((queries.vertexRotationJacobians<float>(current, "crane", {}, far, false, positions_f32,
                                                                    jacobians_f32)),
                            drb::InvalidArgumentError,
                            "q: position too large: vertex positions of body 'crane' would overflow float32");
  EXPECT_EQ(positions, std::vector<double>{ 42.0 });
  EXPECT_EQ(jacobians, std::vector<double>{ 43.0 });
  EXPECT_EQ(positions_f32, std::vector<float>{ 44.0f });
  EXPECT_EQ(jacobians_f32, std::vector<float>{ 45.0f });
}
