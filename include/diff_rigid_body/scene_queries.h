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
#include <unordered_set>
#include <utility>
#include <vector>

#include "diff_rigid_body/articulated_kinematics.h"
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
  /// Jacobians of 2^22 vertices of a free body take 640 MiB). Also the most
  /// configurations.
  static constexpr std::size_t kMaxVertices = std::size_t(1) << 22;
  /// Doubles that a vertex request on an articulated body may need: its
  /// answer, 3 (1 + d) per vertex and configuration, and its motion
  /// matrices, 6 d per segment. The free body's 21 per vertex times
  /// kMaxVertices (640 MiB).
  static constexpr std::size_t kMaxArticulatedDoubles = 21 * kMaxVertices;
  /// Mass matrices (configurations x bodies) of 6-dof bodies in one
  /// get_mass_matrix request; with derivatives each costs 252 doubles (2 KiB).
  static constexpr std::size_t kMaxMassMatrices = 1000000;
  static constexpr std::size_t kMaxMassMatricesWithDerivatives = 100000;
  /// The same limits as budgets of answer doubles, for bodies of any dof:
  /// sum over matrices of dof^2 (M), plus dof^3 with derivatives (dM/dx).
  static constexpr std::size_t kMaxMassMatrixDoubles = kMaxMassMatrices * 36;
  static constexpr std::size_t kMaxMassMatrixDoublesWithDerivatives = kMaxMassMatricesWithDerivatives * (36 + 216);
  /// Entries in one set_state or get_state request; names in one joint_states message.
  static constexpr std::size_t kMaxStates = 100000;
};

/// One x per body, in scene order, len = scene.bodies[i].dofs(): a free
/// body's q = (phi, theta, psi, tx, ty, tz), an articulated body's
/// coordinates (articulated_body.h).
using SceneState = std::vector<Eigen::VectorXd>;

/// Named state of one body, as requests carry it (x, dofs() values).
struct NamedState
{
  std::string name;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
};

/// Matrices in configuration-major order, then the listed bodies' order:
/// matrix (k, i) for configuration k and listed body i, d_i = dofs[i].
struct MassMatrixAnswer
{
  std::vector<std::string> bodies;
  std::vector<std::uint32_t> dofs;    ///< d_i per listed body
  std::vector<double> mass_matrices;  ///< d_i^2 per matrix, row-major
  std::vector<double> derivatives;    ///< d_i^3 per matrix when asked: dM/dx_j, j = 0..d_i-1, d_i^2 row-major each
  /// One per matrix: cos(theta) of a free body or floating root (0 at gimbal
  /// lock); 1 for a fixed-base body (no Euler angles).
  std::vector<double> cos_theta;
};

class SceneQueries
{
public:
  explicit SceneQueries(Scene scene);

  const Scene& scene() const { return scene_; }
  std::size_t bodyCount() const { return scene_.bodies.size(); }
  const RigidBody& body(std::size_t index) const { return scene_.bodies[index].body; }

  /// len(x) of body `index`: 6 for a free body.
  std::size_t dofs(std::size_t index) const { return scene_.bodies[index].dofs(); }

  /// The URDF initial state of every body.
  SceneState initialState() const;

  /// Index of body `name`; throws naming `field` and the known bodies.
  std::size_t bodyIndex(const std::string& name, const std::string& field) const;

  /// Indices of `names` (empty = all bodies, in scene order).
  std::vector<std::size_t> bodyIndices(const std::vector<std::string>& names, const std::string& field) const;

  /// The state after applying `updates` to `current`, all or nothing: an
  /// unknown or repeated name, a q whose length is not the body's dofs, or a
  /// non-finite value rejects the whole request. q is stored bit for bit (no
  /// angle wrapping).
  SceneState applyStates(const SceneState& current, const std::vector<NamedState>& updates) const;

  /// The state after a sensor_msgs/JointState message: each named
  /// independent joint of an articulated body is set (x index
  /// rootCoordinates() + k for joint_names[k]; a repeated name: the last
  /// wins). Names of mimic joints are ignored; any other name is appended to
  /// `unknown_names` and ignored. All or nothing: names and positions of
  /// different lengths, more than RequestLimits::kMaxStates names, or a
  /// non-finite position (of any joint) throws InvalidArgumentError and
  /// changes nothing.
  SceneState applyJointPositions(const SceneState& current, const std::vector<std::string>& names,
                                 const std::vector<double>& positions, std::vector<std::string>& unknown_names) const;

  /// States of `names` (empty = all).
  std::vector<NamedState> getStates(const SceneState& current, const std::vector<std::string>& names) const;

  /// M(x), and dM/dx when `derivatives`, for the bodies `names` (empty = all)
  /// at K configurations given in `q` (each the concatenation of the listed
  /// bodies' x: K D values, D = sum of their dofs), or at `current` when `q`
  /// is empty. At most RequestLimits::kMaxMassMatrixDoubles answer doubles
  /// (...WithDerivatives when `derivatives`).
  MassMatrixAnswer massMatrices(const SceneState& current, const std::vector<std::string>& names,
                                const std::vector<double>& q, bool derivatives) const;

  /// Positions (3 per vertex, fixed frame) and Jacobians dp/dx (3 d per
  /// vertex, 3 x d row-major, d = the body's dofs; 18 for a free body) of
  /// the N selected vertices (empty = all), at the current state when `q` is
  /// empty, else at each of the K configurations in `q` (d K values):
  /// K x N x 3 positions and K x N x 3d values of J, configuration-major,
  /// each configuration computed as a call with its d values alone would
  /// (same bits). K x N is at most RequestLimits::kMaxVertices. A
  /// configuration whose positions or J would not be finite is refused.
  /// Outputs are resized here, and untouched on refusal.
  void vertexJacobians(const SceneState& current, const std::string& body, const std::vector<std::uint32_t>& vertices,
                       const std::vector<double>& q, std::vector<double>& positions,
                       std::vector<double>& jacobians) const;

  /// The reduced transport of vertexJacobians (~get_vertex_jacobians_compact):
  /// positions (3 per vertex) and, unless `positions_only`, J without the
  /// columns that are always I3, stored as Out: double, or float for the
  /// float32 transport. compactColumns(body) values per row:
  ///   free body: Jr = dp/d(phi, theta, psi), 9 per vertex (3x3 row-major);
  ///   articulated, floating root: every column but x[3..5], 3 (d - 3) per vertex;
  ///   articulated, fixed base: every column, 3 d per vertex.
  /// The checks and messages of vertexJacobians; a request whose outputs
  /// would overflow Out is refused before anything is written. K
  /// configurations in `q` as vertexJacobians (configuration-major).
  /// Outputs are resized here (rotation_jacobians to 0 when `positions_only`).
  /// Instantiated for Out = double and float.
  template <typename Out>
  void vertexRotationJacobians(const SceneState& current, const std::string& body,
                               const std::vector<std::uint32_t>& vertices, const std::vector<double>& q,
                               bool positions_only, std::vector<Out>& positions,
                               std::vector<Out>& rotation_jacobians) const;

  /// dL/dx = sum_i J_i^T g_i at each of the K configurations of `q` (d K
  /// values, d = the body's dofs; empty = the current state, K = 1), for
  /// gradients g given as K x N x 3 values (configuration-major: 3 per
  /// selected vertex for each configuration). Returns K x d values,
  /// configuration k's as a call with its x and gradients alone would give
  /// them (same bits).
  std::vector<double> backpropConfigurations(const SceneState& current, const std::string& body,
                                             const std::vector<std::uint32_t>& vertices,
                                             const std::vector<double>& gradients,
                                             const std::vector<double>& q) const;

  /// Columns per row of body `index`'s compact Jacobian (see vertexRotationJacobians).
  std::size_t compactColumns(std::size_t index) const;

  /// backpropConfigurations for one configuration (`q` empty or d values).
  Eigen::VectorXd backprop(const SceneState& current, const std::string& body,
                           const std::vector<std::uint32_t>& vertices, const std::vector<double>& gradients,
                           const std::vector<double>& q) const;

private:
  /// K for a request's `q` (empty = 1, else its size / d), checked against
  /// its size (a multiple of d = dofs(index)), the vertex limit for K x
  /// `vertex_count` and, for an articulated body, its work limit.
  std::size_t configurationCount(const std::vector<double>& q, std::size_t index, std::size_t vertex_count) const;
  /// Refuses a vertex request on articulated body `index` whose answer
  /// (3 (1 + d) doubles per vertex and configuration) or per-segment motion
  /// matrices (6 d per segment) exceed RequestLimits::kMaxArticulatedDoubles.
  void checkArticulatedWork(std::size_t index, std::size_t configurations, std::size_t vertex_count) const;
  /// The d values of configuration k of body `index`: q + d k, or the current state when `q` is empty.
  const double* configurationQ(const SceneState& current, std::size_t index, const std::vector<double>& q,
                               std::size_t k) const;
  /// Refuses, naming the configuration when there are several, a
  /// configuration whose bound |t|_inf + inflation max_i |p0_i| on every
  /// output exceeds `limit` ("... would overflow<suffix>").
  void checkPositionsFit(const SceneState& current, std::size_t index, const std::vector<double>& q,
                         std::size_t configurations, double inflation, double limit, const char* suffix) const;
  /// Refuses a get_mass_matrix answer over the budget of doubles.
  void checkMassMatrixBudget(std::size_t configurations, std::size_t bodies, std::size_t per_configuration,
                             bool all_free, bool derivatives, std::size_t q_size) const;
  /// Checks every index of `vertices` against body `index`.
  std::size_t checkVertices(std::size_t index, const std::vector<std::uint32_t>& vertices) const;
  /// The articulated pose of configuration k, refused ("... would overflow")
  /// if a segment frame is not finite.
  ArticulatedPose<double> checkedPose(const SceneState& current, std::size_t index, const std::vector<double>& q,
                                      std::size_t configurations, std::size_t k) const;
  /// Positions and the J `columns` (empty = all) of an articulated body's
  /// vertices, stored as Out; refused if a value would exceed max(Out).
  template <typename Out>
  void articulatedCompact(const SceneState& current, std::size_t index, const std::vector<std::uint32_t>& vertices,
                          std::size_t count, const std::vector<double>& q, std::size_t configurations,
                          bool positions_only, const std::vector<int>& columns, std::vector<Out>& positions,
                          std::vector<Out>& jacobians) const;

  Scene scene_;
  std::vector<double> vertex_radius_;  ///< max_i |p0_i| per body [m]
  /// Each body's vertices stored by coordinate, for the backprop of all
  /// vertices (vertex_columns.h; 24 B per vertex).
  std::vector<VertexColumns<double>> vertex_columns_;
  /// Body name -> index: O(1) lookups, so that a request of 10^5 states on a
  /// scene of 10^5 bodies is not quadratic.
  std::unordered_map<std::string, std::size_t> body_index_;
  /// Independent joint name -> (body, x index), and the names of mimic joints.
  std::unordered_map<std::string, std::pair<std::size_t, std::size_t>> joint_index_;
  std::unordered_set<std::string> mimic_joints_;
};

/// Throws InvalidArgumentError("<field>[<i>]: not finite (...)") for the first
/// non-finite value.
void requireFinite(const double* values, std::size_t count, const std::string& field);

}  // namespace diff_rigid_body
