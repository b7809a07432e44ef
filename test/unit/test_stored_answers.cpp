// Stored answers: what the public SceneQueries API answered at commit
// 28febbe (before the one-body-model restructuring) for seven scenes, kept
// in test/data/stored_answers/<file>.txt (one file per URDF; format:
// test/support/stored_answers.h) and compared with what it answers now.
//
// Per scene: the body names (getStates), dofs, a fingerprint of the URDF
// text (meshes are not fingerprinted) and M of all bodies at the
// initial state in one call. Per body, at K configurations (the initial
// state, two random ones and, for a body with a floating root, one 1e-7 rad
// from gimbal lock): M and cos(theta) with and without dM/dx;
// positions and J of a spread subset of vertices (full J, and the compact
// transport as float64 and float32), of all vertices for small bodies;
// backprop for the subset and for all vertices.
//
// Free bodies (a floating joint and no joints below it) must answer bit for
// bit, except backprop; articulated bodies within 8 DBL_EPSILON
// max(1, max|stored|) per entry, or one float ulp for float32 (the
// restructuring may reorder sums). Backprop is always compared within that
// tolerance: its summation engine (detail/backprop_sums.h) sums in AVX-512,
// AVX2 or portable lanes as the CPU has them, so the order of its sums,
// and their last bits, depend on the machine.
//
// Regenerating: DRB_WRITE_STORED_ANSWERS=<dir> test_core
// --gtest_filter='StoredAnswers*' writes <dir>/<file>.txt instead of
// comparing (and passes with a note); copy them to test/data/stored_answers.
// That is legitimate only when an answer change is intended: say which
// answers change and why where the new files are committed.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "../support/articulated_fixtures.h"
#include "../support/stored_answers.h"

namespace drb = diff_rigid_body;
using drb_test::stored_answers::AnswerBook;
using drb_test::stored_answers::Match;

namespace
{
const std::string kTestDir = DRB_TEST_DATA_DIR;  // <checkout>/test
const double kHalfPi = 1.5707963267948966;
/// Vertices of the spread subset of each body (first and last included):
/// a free body's vertices all take the same arithmetic (and must match bit
/// for bit), an articulated body's should come from several segments.
constexpr std::size_t kFreeSubsetVertices = 4;
constexpr std::size_t kArticulatedSubsetVertices = 10;
/// Bodies whose all-vertex vertexJacobians answer (K N 3 (1 + d) values)
/// is at most this large store it (the data files stay small).
constexpr std::size_t kAllVerticesMostValues = 1500;

/// Free: x = (phi, theta, psi, tx, ty, tz), compared bit for bit.
/// FloatingRoot: articulated, x = (phi, theta, psi, t, joints).
/// FixedBase: articulated, x = joints.
enum class Kind
{
  Free,
  FloatingRoot,
  FixedBase
};

struct SceneSpec
{
  std::string label;  ///< the first part of its keys
  std::string path;   ///< URDF file; empty: `urdf` is the text
  std::string urdf;
  drb::JointHandling joints = drb::JointHandling::Model;
  std::vector<std::pair<std::string, Kind>> bodies;  ///< expected, in scene order
};

/// package://diff_rigid_body (the checkout) and package://drb_example_robot_data (test/robots).
drb::SceneOptions optionsFor(const SceneSpec& spec)
{
  drb::SceneOptions options;
  options.joints = spec.joints;
  options.find_package = [](const std::string& package) -> std::string {
    if (package == "diff_rigid_body")
      return kTestDir + "/..";
    return package == "drb_example_robot_data" ? kTestDir + "/robots/drb_example_robot_data" : "";
  };
  return options;
}

SceneSpec fileScene(std::string label, const std::string& path, drb::JointHandling joints,
                    std::vector<std::pair<std::string, Kind>> bodies)
{
  return { std::move(label), path, drb_test::articulated::readText(path), joints, std::move(bodies) };
}

std::vector<SceneSpec> scenes()
{
  const std::string erd = drb_test::articulated::kErd + "/";
  const auto model = drb::JointHandling::Model;
  const auto free = drb::JointHandling::Free;
  const std::string fixture = kTestDir + "/urdf/fixture_scene.urdf";
  return {
    fileScene("demo_scene", kTestDir + "/../urdf/demo_scene.urdf", model,
              { { "knot", Kind::Free }, { "rock", Kind::Free } }),
    fileScene("fixture_scene", fixture, model,
              { { "brick", Kind::Free }, { "tet", Kind::Free }, { "roller", Kind::FixedBase } }),
    fileScene("fixture_scene_free_joints", fixture, free,
              { { "brick", Kind::Free }, { "tet", Kind::Free }, { "roller", Kind::Free } }),
    fileScene("panda", erd + "panda_description/urdf/panda.urdf", model, { { "panda_link1", Kind::FixedBase } }),
    fileScene("ur5", erd + "ur_description/urdf/ur5_robot.urdf", model, { { "shoulder_link", Kind::FixedBase } }),
    fileScene("double_pendulum", erd + "double_pendulum_description/urdf/double_pendulum.urdf", model,
              { { "link1", Kind::FixedBase } }),
    { "floating_tree", "", drb_test::articulated::floatingTreeUrdf(), model, { { "torso", Kind::FloatingRoot } } },
  };
}

drb::Scene load(const SceneSpec& spec)
{
  return spec.path.empty() ? drb::loadSceneFromUrdf(spec.urdf, optionsFor(spec)) :
                             drb::loadSceneFromUrdfFile(spec.path, optionsFor(spec));
}

/// Uniform in [lo, hi) from the top 53 bits of one mt19937_64 draw. Written
/// out because std::uniform_real_distribution's conversion is left to the
/// standard library, and the stored configurations must not depend on it.
double uniform(std::mt19937_64& rng, double lo, double hi)
{
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1p-53);
}

/// The body's inputs: K configurations (d values each), the spread vertex
/// subset and gradients dL/dp in [-1, 1) for it and for all vertices.
struct BodyInputs
{
  std::string name;
  Kind kind = Kind::Free;
  std::size_t dofs = 0;
  std::size_t vertex_count = 0;
  std::size_t configurations = 0;  ///< K
  std::vector<double> q;           ///< K x d, configuration-major
  std::vector<std::uint32_t> subset;
  std::vector<double> subset_gradients;  ///< K x subset x 3
  std::vector<double> all_gradients;     ///< K x vertex_count x 3
};

/// The initial state, then two random configurations: angles in [-2, 2) rad,
/// translations in [-1, 1) m, joints in [-1.5, 1.5) rad or m; with a floating
/// root a third, random but for theta = pi/2 - 1e-7 (cos(theta) ~ 1e-7).
std::vector<double> configurations(const Eigen::VectorXd& initial, Kind kind, std::mt19937_64& rng)
{
  const bool floating = kind != Kind::FixedBase;
  std::vector<double> q(initial.data(), initial.data() + initial.size());
  for (int c = 0; c < (floating ? 3 : 2); ++c)
    for (Eigen::Index i = 0; i < initial.size(); ++i)
    {
      double x = floating && i < 3 ? uniform(rng, -2, 2) :
                 floating && i < 6 ? uniform(rng, -1, 1) : uniform(rng, -1.5, 1.5);
      if (c == 2 && i == 1)
        x = kHalfPi - 1e-7;
      q.push_back(x);
    }
  return q;
}

/// `most` indices spread evenly over [0, count - 1], both ends included.
std::vector<std::uint32_t> spreadVertices(std::size_t count, std::size_t most)
{
  const std::size_t n = std::min(count, most);
  std::vector<std::uint32_t> indices;
  for (std::size_t i = 0; i < n; ++i)
    indices.push_back(static_cast<std::uint32_t>(n == 1 ? 0 : i * (count - 1) / (n - 1)));
  return indices;
}

std::vector<double> gradients(std::size_t count, std::mt19937_64& rng)
{
  std::vector<double> g(count);
  for (double& value : g)
    value = uniform(rng, -1, 1);
  return g;
}

/// Inputs of body `name` (scene index `index`), seeded by its name: a body
/// in two scenes of one URDF gets the same inputs.
BodyInputs bodyInputs(const drb::SceneQueries& queries, const drb::SceneState& state, std::size_t index,
                      const std::string& name, Kind kind)
{
  BodyInputs in;
  in.name = name;
  in.kind = kind;
  in.dofs = queries.dofs(index);
  std::vector<double> positions, unused;
  queries.vertexRotationJacobians<double>(state, name, {}, {}, true, positions, unused);
  in.vertex_count = positions.size() / 3;
  std::mt19937_64 rng(drb_test::stored_answers::fnv1a64(name));
  in.q = configurations(state[index], kind, rng);
  in.configurations = in.q.size() / in.dofs;
  in.subset = spreadVertices(in.vertex_count, kind == Kind::Free ? kFreeSubsetVertices : kArticulatedSubsetVertices);
  in.subset_gradients = gradients(in.configurations * in.subset.size() * 3, rng);
  in.all_gradients = gradients(in.configurations * in.vertex_count * 3, rng);
  return in;
}

void massAnswers(const drb::SceneQueries& queries, const drb::SceneState& state, const BodyInputs& in,
                 Match match, AnswerBook& book)
{
  const drb::MassMatrixAnswer plain = queries.massMatrices(state, { in.name }, in.q, false);
  book.numbers(in.name, "mass_matrices/M", plain.mass_matrices, match);
  book.numbers(in.name, "mass_matrices/cos_theta", plain.cos_theta, match);
  const drb::MassMatrixAnswer full = queries.massMatrices(state, { in.name }, in.q, true);
  book.numbers(in.name, "mass_matrices_with_derivatives/M", full.mass_matrices, match);
  book.numbers(in.name, "mass_matrices_with_derivatives/dM", full.derivatives, match);
  book.numbers(in.name, "mass_matrices_with_derivatives/cos_theta", full.cos_theta, match);
}

/// Full J (3 x d per vertex), the compact transport as float64 and float32,
/// for the subset, and the full J of all vertices of a small body.
void vertexAnswers(const drb::SceneQueries& queries, const drb::SceneState& state, const BodyInputs& in,
                   Match match, AnswerBook& book)
{
  std::vector<double> positions, jacobians;
  queries.vertexJacobians(state, in.name, in.subset, in.q, positions, jacobians);
  book.numbers(in.name, "vertex_jacobians/subset/positions", positions, match);
  book.numbers(in.name, "vertex_jacobians/subset/J", jacobians, match);
  queries.vertexRotationJacobians<double>(state, in.name, in.subset, in.q, false, positions, jacobians);
  book.numbers(in.name, "compact_f64/subset/positions", positions, match);
  book.numbers(in.name, "compact_f64/subset/J", jacobians, match);
  std::vector<float> positions32, jacobians32;
  queries.vertexRotationJacobians<float>(state, in.name, in.subset, in.q, false, positions32, jacobians32);
  book.numbers(in.name, "compact_f32/subset/positions", positions32, match);
  book.numbers(in.name, "compact_f32/subset/J", jacobians32, match);
  if (in.configurations * in.vertex_count * 3 * (1 + in.dofs) > kAllVerticesMostValues)
    return;
  queries.vertexJacobians(state, in.name, {}, in.q, positions, jacobians);
  book.numbers(in.name, "vertex_jacobians/all/positions", positions, match);
  book.numbers(in.name, "vertex_jacobians/all/J", jacobians, match);
}

/// dL/dx = sum_i J_i^T g_i: subset and all vertices at the K configurations,
/// and the subset at the current state (q empty; the first K block of g),
/// within the tolerance on every CPU (see the header comment).
void backpropAnswers(const drb::SceneQueries& queries, const drb::SceneState& state, const BodyInputs& in,
                     AnswerBook& book)
{
  const Match match = Match::Tolerance;
  book.numbers(in.name, "backprop/subset",
               queries.backpropConfigurations(state, in.name, in.subset, in.subset_gradients, in.q), match);
  book.numbers(in.name, "backprop/all",
               queries.backpropConfigurations(state, in.name, {}, in.all_gradients, in.q), match);
  const std::vector<double> first(in.subset_gradients.begin(),
                                  in.subset_gradients.begin() + static_cast<long>(in.subset.size() * 3));
  book.numbers(in.name, "backprop/subset/current_state",
               queries.backpropConfigurations(state, in.name, in.subset, first, {}), match);
}

/// M of all bodies (names empty) at the current state, split per body.
void sceneMassAnswers(const drb::SceneQueries& queries, const drb::SceneState& state,
                      const std::vector<BodyInputs>& bodies, const std::vector<Match>& matches, AnswerBook& book)
{
  const drb::MassMatrixAnswer all = queries.massMatrices(state, {}, {}, false);
  ASSERT_EQ(all.bodies.size(), bodies.size());
  std::size_t m = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i)
  {
    const std::size_t d = bodies[i].dofs;
    ASSERT_EQ(all.bodies[i], bodies[i].name);
    ASSERT_LE(m + d * d, all.mass_matrices.size());
    const auto slice = [](const std::vector<double>& v, std::size_t first, std::size_t n) {
      return std::vector<double>(v.begin() + static_cast<long>(first), v.begin() + static_cast<long>(first + n));
    };
    const std::string prefix = "mass_matrices/all_bodies_current_state/";
    book.numbers(bodies[i].name, prefix + "M", slice(all.mass_matrices, m, d * d), matches[i]);
    book.numbers(bodies[i].name, prefix + "cos_theta", slice(all.cos_theta, i, 1), matches[i]);
    m += d * d;
  }
}

/// The body's kind as the spec lists it; a body it does not list is compared
/// within tolerance, and fails.
Kind kindOf(const SceneSpec& spec, const std::string& name)
{
  for (const auto& body : spec.bodies)
    if (body.first == name)
      return body.second;
  ADD_FAILURE() << spec.label << ": body '" << name << "' is not in the test's list of expected bodies";
  return Kind::FixedBase;
}

void checkScene(const SceneSpec& spec, AnswerBook& book)
{
  book.beginScene(spec.label);
  const drb::SceneQueries queries(load(spec));
  const drb::SceneState state = queries.initialState();
  const std::vector<drb::NamedState> states = queries.getStates(state, {});
  std::vector<std::string> names;
  std::vector<double> dofs;
  std::vector<BodyInputs> bodies;
  std::vector<Match> matches;
  for (std::size_t i = 0; i < states.size(); ++i)
  {
    names.push_back(states[i].name);
    dofs.push_back(static_cast<double>(queries.dofs(i)));
    bodies.push_back(bodyInputs(queries, state, i, states[i].name, kindOf(spec, states[i].name)));
    matches.push_back(bodies.back().kind == Kind::Free ? Match::Exact : Match::Tolerance);
    if (bodies.back().kind == Kind::Free)
    {
      EXPECT_EQ(queries.dofs(i), 6u) << spec.label << ": free body '" << names.back() << "'";
    }
  }
  book.names("", "urdf_fnv1a64", { drb_test::stored_answers::fingerprint(spec.urdf) });
  book.names("", "bodies", names);
  book.numbers("", "dofs", dofs, Match::Exact);
  for (std::size_t i = 0; i < bodies.size(); ++i)
  {
    const BodyInputs& in = bodies[i];
    const std::vector<double> initial(states[i].x.data(), states[i].x.data() + states[i].x.size());
    book.numbers(in.name, "initial_state", initial, matches[i]);
    book.numbers(in.name, "vertex_count", std::vector<double>{ double(in.vertex_count) }, Match::Exact);
    // Configurations 1..K-1 are the test's own numbers (configuration 0 is
    // the initial state, an answer).
    book.numbers(in.name, "inputs/random_q", std::vector<double>(in.q.begin() + static_cast<long>(in.dofs), in.q.end()),
                 Match::Exact);
    massAnswers(queries, state, in, matches[i], book);
    vertexAnswers(queries, state, in, matches[i], book);
    backpropAnswers(queries, state, in, book);
  }
  sceneMassAnswers(queries, state, bodies, matches, book);
}

/// The scenes `labels` against (or into) test/data/stored_answers/<file>.txt.
void checkFile(const std::string& file, const std::vector<std::string>& labels)
{
  const char* write_dir = std::getenv("DRB_WRITE_STORED_ANSWERS");
  AnswerBook book(file, kTestDir + "/data/stored_answers", write_dir ? write_dir : "");
  for (const std::string& label : labels)
  {
    bool found = false;
    for (const SceneSpec& spec : scenes())
      if (spec.label == label)
      {
        checkScene(spec, book);
        found = true;
      }
    EXPECT_TRUE(found) << "no scene " << label;
  }
  book.finish();
}
}  // namespace

TEST(StoredAnswers, DemoScene) { checkFile("demo_scene", { "demo_scene" }); }
// One file: the free bodies brick and tet answer the same in both, and are stored once.
TEST(StoredAnswers, FixtureScene) { checkFile("fixture_scene", { "fixture_scene", "fixture_scene_free_joints" }); }
TEST(StoredAnswers, Panda) { checkFile("panda", { "panda" }); }
TEST(StoredAnswers, Ur5) { checkFile("ur5", { "ur5" }); }
TEST(StoredAnswers, DoublePendulum) { checkFile("double_pendulum", { "double_pendulum" }); }
TEST(StoredAnswers, FloatingTree) { checkFile("floating_tree", { "floating_tree" }); }
