// The queries the node serves, on plain arrays: request validation, state
// snapshots and evaluation. ROS-free, so that the service logic is unit-tested
// and fuzzed without a master; the node only copies message fields in and out.
//
// Every function validates its whole request before it allocates or writes
// anything, and throws InvalidArgumentError naming the field, index or body.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "diff_rigid_body/urdf_scene.h"
#include "diff_rigid_body/vertex_columns.h"

namespace diff_rigid_body
{
/// Documented request limits; a request over one is refused before anything
/// is allocated for it.
struct RequestLimits
{
  /// Vertices in one get_vertex_jacobians or backprop request, over all its
  /// configurations (K x N for K configurations of N vertices; positions and
  /// Jacobians of 2^22 vertices take 640 MiB). Also the most configurations.
  static constexpr std::size_t kMaxVertices = std::size_t(1) << 22;
  /// Mass matrices (configurations x bodies) in one get_mass_matrix request;
  /// with derivatives each costs 252 doubles (2 KiB).
  static constexpr std::size_t kMaxMassMatrices = 1000000;
  static constexpr std::size_t kMaxMassMatricesWithDerivatives = 100000;
  /// Entries in one set_state or get_state request.
  static constexpr std::size_t kMaxStates = 100000;
};

/// One state q = (phi, theta, psi, tx, ty, tz) per body, in scene order.
using SceneState = std::vector<Vector6<double>>;

/// Named state of one body, as requests carry it.
struct NamedState
{
  std::string name;
  Vector6<double> q = Vector6<double>::Zero();
};

struct MassMatrixAnswer
{
  std::vector<std::string> bodies;
  std::vector<double> mass_matrices;  ///< 36 per matrix, row-major, matrix (k n + i) for configuration k, body i
  std::vector<double> derivatives;    ///< 216 per matrix when asked: dM/dq_j, j = 0..5, 36 row-major each
  std::vector<double> cos_theta;      ///< one per matrix
};

class SceneQueries
{
public:
  explicit SceneQueries(Scene scene);

  const Scene& scene() const { return scene_; }
  std::size_t bodyCount() const { return scene_.bodies.size(); }
  const RigidBody& body(std::size_t index) const { return scene_.bodies[index].body; }

  /// The URDF initial state of every body.
  SceneState initialState() const;

  /// Index of body `name`; throws naming `field` and the known bodies.
  std::size_t bodyIndex(const std::string& name, const std::string& field) const;

  /// Indices of `names` (empty = all bodies, in scene order).
  std::vector<std::size_t> bodyIndices(const std::vector<std::string>& names, const std::string& field) const;

  /// The state after applying `updates` to `current`, all or nothing: an
  /// unknown or repeated name or a non-finite value rejects the whole request.
  /// q is stored bit for bit (no angle wrapping).
  SceneState applyStates(const SceneState& current, const std::vector<NamedState>& updates) const;

  /// States of `names` (empty = all).
  std::vector<NamedState> getStates(const SceneState& current, const std::vector<std::string>& names) const;

  /// M(q), and dM/dq when `derivatives`, for the bodies `names` (empty = all)
  /// at K configurations given in `q` (K 6 n values), or at `current` when `q`
  /// is empty.
  MassMatrixAnswer massMatrices(const SceneState& current, const std::vector<std::string>& names,
                                const std::vector<double>& q, bool derivatives) const;

  /// Positions (3 per vertex, fixed frame) and Jacobians (18 per vertex, 3x6
  /// row-major) of the N selected vertices (empty = all), at the current
  /// state when `q` is empty, else at each of the K configurations in `q`
  /// (6 K values): K x N x 3 positions and K x N x 18 values of J,
  /// configuration-major, each configuration computed as a call with its 6
  /// values alone would (same bits). K x N is at most
  /// RequestLimits::kMaxVertices. Outputs are resized here.
  void vertexJacobians(const SceneState& current, const std::string& body, const std::vector<std::uint32_t>& vertices,
                       const std::vector<double>& q, std::vector<double>& positions,
                       std::vector<double>& jacobians) const;

  /// The reduced transport of vertexJacobians (~get_vertex_jacobians_compact):
  /// positions (3 per vertex) and, unless `positions_only`, the rotation
  /// block Jr = dp/d(phi, theta, psi) (9 per vertex, 3x3 row-major; the
  /// translation block is always I3), stored as Out: double, or float for
  /// the float32 transport. The checks and messages of vertexJacobians; a
  /// request whose outputs would overflow Out is refused before anything is
  /// written. K configurations in `q` as vertexJacobians (K x N x 3
  /// positions, K x N x 9 rotation_jacobians, configuration-major). Outputs
  /// are resized here (rotation_jacobians to 0 when `positions_only`).
  /// Instantiated for Out = double and float.
  template <typename Out>
  void vertexRotationJacobians(const SceneState& current, const std::string& body,
                               const std::vector<std::uint32_t>& vertices, const std::vector<double>& q,
                               bool positions_only, std::vector<Out>& positions,
                               std::vector<Out>& rotation_jacobians) const;

  /// dL/dq = sum_i J_i^T g_i at each of the K configurations of `q` (6 K
  /// values; empty = the current state, K = 1), for gradients g given as
  /// K x N x 3 values (configuration-major: 3 per selected vertex for each
  /// configuration). Returns K x 6 values, configuration k's as a call with
  /// its q and gradients alone would give them (same bits).
  std::vector<double> backpropConfigurations(const SceneState& current, const std::string& body,
                                             const std::vector<std::uint32_t>& vertices,
                                             const std::vector<double>& gradients,
                                             const std::vector<double>& q) const;

  /// backpropConfigurations for one configuration (`q` empty or 6 values).
  Vector6<double> backprop(const SceneState& current, const std::string& body,
                           const std::vector<std::uint32_t>& vertices, const std::vector<double>& gradients,
                           const std::vector<double>& q) const;

private:
  /// K for a request's `q` (empty = 1, else its size / 6), checked against
  /// its size (a multiple of 6) and the vertex limit for K x `vertex_count`.
  std::size_t configurationCount(const std::vector<double>& q, std::size_t vertex_count) const;
  /// The 6 values of configuration k of body `index`: q + 6 k, or the current state when `q` is empty.
  const double* configurationQ(const SceneState& current, std::size_t index, const std::vector<double>& q,
                               std::size_t k) const;
  /// Refuses, naming the configuration when there are several, a
  /// configuration whose bound |t|_inf + inflation max_i |p0_i| on every
  /// output exceeds `limit` ("... would overflow<suffix>").
  void checkPositionsFit(const SceneState& current, std::size_t index, const std::vector<double>& q,
                         std::size_t configurations, double inflation, double limit, const char* suffix) const;
  /// Checks every index of `vertices` against body `index`.
  std::size_t checkVertices(std::size_t index, const std::vector<std::uint32_t>& vertices) const;

  Scene scene_;
  std::vector<double> vertex_radius_;  ///< max_i |p0_i| per body [m]
  /// Each body's vertices stored by coordinate, for the backprop of all
  /// vertices (vertex_columns.h; 24 B per vertex).
  std::vector<VertexColumns<double>> vertex_columns_;
  /// Body name -> index: O(1) lookups, so that a request of 10^5 states on a
  /// scene of 10^5 bodies is not quadratic.
  std::unordered_map<std::string, std::size_t> body_index_;
};

/// Throws InvalidArgumentError("<field>[<i>]: not finite (...)") for the first
/// non-finite value.
void requireFinite(const double* values, std::size_t count, const std::string& field);

}  // namespace diff_rigid_body
