// The queries the node serves, on plain arrays: request validation, state
// snapshots and evaluation. ROS-free, so that the service logic is unit-tested
// and fuzzed without a master; the node only copies message fields in and out.
//
// Every function validates its whole request before it allocates or writes
// anything, and throws InvalidArgumentError naming the field, index or body.
// Float64 request arrays (q, qdot, qddot, tau, gradients) are DoubleViews
// (services/array_view.h): read in place, from a message's vectors or a caller's own
// buffers, for the duration of the call.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "diff_rigid_body/services/array_view.h"
#include "diff_rigid_body/services/service_tables.h"  // generated from srv/*.srv
#include "diff_rigid_body/multibody/body_workspace.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "diff_rigid_body/algorithm/vertex_jacobians.h"

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
  /// Doubles in the answer of one vertex request on a body of any dof:
  /// 3 (1 + written columns) per vertex and configuration; the free body's
  /// 21 per vertex times kMaxVertices (640 MiB).
  static constexpr std::size_t kMaxVertexAnswerDoubles = 21 * kMaxVertices;
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

/// One x per body, in scene order, len = scene.bodies[i].coordinates: a free
/// object's q = (phi, theta, psi, tx, ty, tz), a tree's coordinates
/// (body_model.h).
using SceneState = std::vector<Eigen::VectorXd>;

/// Named state of one body, as requests carry it: its x (d values).
struct NamedState
{
  std::string name;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(6);
};

// The batched answers, each declared from its .srv response's fields:
// DRB_<Type>_RESPONSE_FIELDS(X), X(type, name) in the response's order, is
// written from srv/<Type>.srv at configure time (service_tables.h). DRB_ANSWER
// declares the fields and moveInto(response), which moves each field into the
// member of the same name of any struct that has them (the node's srv
// response): a field is named once, in its .srv, for the core and the node.
#define DRB_ANSWER_FIELD(type, name) type name{};
#define DRB_ANSWER_MOVE(type, name) response.name = std::move(name);
#define DRB_ANSWER(FIELDS)                                                                                             \
  FIELDS(DRB_ANSWER_FIELD)                                                                                             \
  template <typename Response>                                                                                         \
  void moveInto(Response& response)                                                                                    \
  {                                                                                                                    \
    FIELDS(DRB_ANSWER_MOVE)                                                                                            \
  }

/// ~get_mass_matrix: matrices in configuration-major order, then the listed
/// bodies' order: matrix (k, i) for configuration k and listed body i,
/// d_i = dofs[i]. mass_matrices: d_i^2 per matrix, row-major; derivatives:
/// d_i^3 per matrix when asked, dM/dx_j for j = 0..d_i-1, d_i^2 row-major
/// each; cos_theta: one per matrix, cos(theta) of a free body or floating
/// root (0 at gimbal lock), 1 for a fixed-base body (no Euler angles).
struct MassMatrixAnswer
{
  DRB_ANSWER(DRB_GetMassMatrix_RESPONSE_FIELDS)
};

/// ~inverse_dynamics, laid out as MassMatrixAnswer: per configuration k and
/// listed body i, vectors of d_i values at k D + (sum of the d before i) and
/// matrices of d_i^2 (row-major) at k sum(d^2) + (sum of the d^2 before i).
/// tau = M x'' + c + g, velocity_terms c = C x', gravity_terms g; when asked,
/// coriolis_matrices C, dtau_dq and dtau_dqdot (= 2 C); cos_theta per
/// matrix slot, as MassMatrixAnswer.
struct InverseDynamicsAnswer
{
  DRB_ANSWER(DRB_InverseDynamics_RESPONSE_FIELDS)
};

/// ~forward_dynamics, laid out as InverseDynamicsAnswer: qddot =
/// M^-1 (tau - c - g); when asked dqddot_dq, dqddot_dqdot and dqddot_dtau
/// (= M^-1).
struct ForwardDynamicsAnswer
{
  DRB_ANSWER(DRB_ForwardDynamics_RESPONSE_FIELDS)
};

/// ~get_frame_jacobians: per configuration k and listed frame f
/// (frame-major within a configuration), slot n = k F + f of F frames.
/// dofs: d of the body; poses: 12 per slot, the position, then the rotation
/// row-major; jacobians: 6 d per slot, row-major, rows linear then angular;
/// acceleration_bias: 6 per slot, when asked; cos_theta: one per
/// configuration, as MassMatrixAnswer.
struct FrameJacobianAnswer
{
  DRB_ANSWER(DRB_GetFrameJacobians_RESPONSE_FIELDS)
};

/// ~get_center_of_mass: per configuration k and listed body i (body-major
/// within a configuration), slot n = k n_bodies + i. masses per listed body
/// [kg]; com: 3 per slot, fixed frame [m]; when asked, jacobians (3 d_i per
/// slot, row-major) and acceleration_bias (3 per slot [m/s^2]); cos_theta
/// per slot.
struct CenterOfMassAnswer
{
  DRB_ANSWER(DRB_GetCenterOfMass_RESPONSE_FIELDS)
};

/// ~get_vertex_jacobians: positions and jacobians as vertexJacobians writes them.
struct VertexJacobiansAnswer
{
  DRB_ANSWER(DRB_GetVertexJacobians_RESPONSE_FIELDS)
};

/// ~backprop: gradient as backpropConfigurations writes it.
struct BackpropAnswer
{
  DRB_ANSWER(DRB_Backprop_RESPONSE_FIELDS)
};

/// ~get_vertex_jacobians_compact: positions and rotation_jacobians as
/// vertexRotationJacobians<double> writes them, or the *_f32 pair as
/// vertexRotationJacobians<float> does (the other pair left empty).
struct VertexJacobiansCompactAnswer
{
  DRB_ANSWER(DRB_GetVertexJacobiansCompact_RESPONSE_FIELDS)
};

/// ~get_bodies: per body (n of them), then per joint coordinate and per link,
/// flattened in scene order, named as in srv/GetBodies.srv. Matrices are
/// row-major; units [kg], [kg m^2], [m], [rad or m]. fixed_frame: without any
/// frame prefix; names: each body's root link; masses: the total of its
/// links; inertias (9 per body): the root link's group about its COM, root
/// link axes; com_offsets (3 per body): that group's COM in the root link
/// frame; dofs: d = len(x); joint_names: the joints of x, body after body,
/// with joint_counts per body and their limits (+-inf where none);
/// link_names: body after body in vertex order, with link_counts per body and
/// per link its vertices, mass, inertia about its COM in link axes (9) and
/// COM in its own frame (3).
struct BodiesAnswer
{
  DRB_ANSWER(DRB_GetBodies_RESPONSE_FIELDS)
};

/// Standard gravity in the fixed frame, -9.81 m/s^2 along z (~gravity's default).
inline Eigen::Vector3d standardGravity()
{
  return Eigen::Vector3d(0.0, 0.0, -9.81);
}

class SceneQueries
{
public:
  /// `gravity`: gamma in the fixed frame [m/s^2] (~gravity), for the dynamics.
  explicit SceneQueries(Scene scene, const Eigen::Vector3d& gravity = standardGravity());

  const Eigen::Vector3d& gravity() const { return gravity_; }

  const Scene& scene() const { return scene_; }
  std::size_t bodyCount() const { return scene_.bodies.size(); }
  const BodyModel& body(std::size_t index) const { return scene_.bodies[index]; }

  /// d = len(x) of body `index`: 6 for a free object.
  std::size_t dofs(std::size_t index) const { return scene_.bodies[index].coordinates; }

  /// The URDF initial state of every body.
  SceneState initialState() const;

  /// Index of body `name`; throws naming `field` and the known bodies.
  std::size_t bodyIndex(const std::string& name, const std::string& field) const;

  /// Indices of `names` (empty = all bodies, in scene order), into `indices`
  /// (its buffer reused), or returned.
  void bodyIndices(const std::vector<std::string>& names, const char* field, std::vector<std::size_t>& indices) const;
  std::vector<std::size_t> bodyIndices(const std::vector<std::string>& names, const char* field) const;

  /// The state after applying `updates` to `current`, all or nothing: an
  /// unknown or repeated name, an x whose length is not the body's d, a
  /// non-finite value, or link poses that overflow rejects the whole
  /// request. x is stored bit for bit (no angle wrapping).
  SceneState applyStates(const SceneState& current, const std::vector<NamedState>& updates) const;

  /// The state after a sensor_msgs/JointState message: each named
  /// independent joint is set (x index rootCoordinates() + k for
  /// joint_names[k]; a repeated name: the last wins). Names of mimic joints
  /// are ignored; any other name is appended to `unknown_names` and ignored.
  /// All or nothing: names and positions of different lengths, more than
  /// RequestLimits::kMaxStates names, a non-finite position (of any joint)
  /// or overflowing link poses throws InvalidArgumentError and changes nothing.
  SceneState applyJointPositions(const SceneState& current, const std::vector<std::string>& names,
                                 const std::vector<double>& positions, std::vector<std::string>& unknown_names) const;

  /// States of `names` (empty = all).
  std::vector<NamedState> getStates(const SceneState& current, const std::vector<std::string>& names) const;

  /// Pose in the fixed frame of every link of body `index` at x, in
  /// body(index).links order (tf): linkPoses of kinematics.h.
  void linkPoses(std::size_t index, const Eigen::VectorXd& x, std::vector<Eigen::Isometry3d>& poses) const;

  /// M(x), and dM/dx when `derivatives`, for the bodies `bodies` (empty = all)
  /// at K configurations given in `q` (each the concatenation of the listed
  /// bodies' x: K D values, D = sum of their d), or at `current` when `q` is
  /// empty. At most RequestLimits::kMaxMassMatrixDoubles answer doubles
  /// (...WithDerivatives when `derivatives`). `answer` is overwritten (its
  /// buffers reused); on refusal it holds no answer.
  void massMatrices(const SceneState& current, const std::vector<std::string>& bodies, DoubleView q,
                    bool derivatives, MassMatrixAnswer& answer) const;
  MassMatrixAnswer massMatrices(const SceneState& current, const std::vector<std::string>& bodies,
                                DoubleView q, bool derivatives) const;

  /// Positions (3 per vertex, fixed frame) and Jacobians dp/dx (3 d per
  /// vertex, 3 x d row-major; 18 for a free object) of the N selected
  /// vertices (empty = all), at the current state when `q` is empty, else at
  /// each of the K configurations in `q` (d K values): K x N x 3 positions
  /// and K x N x 3d values of J, configuration-major, each configuration
  /// computed as a call with its d values alone would (same bits). K x N is
  /// at most RequestLimits::kMaxVertices, and the answer at most
  /// kMaxVertexAnswerDoubles. A configuration whose outputs could overflow
  /// is refused (vertexOutputBound). Outputs are resized here, and untouched
  /// on refusal.
  void vertexJacobians(const SceneState& current, const std::string& body, const std::vector<std::uint32_t>& vertices,
                       DoubleView q, std::vector<double>& positions,
                       std::vector<double>& jacobians) const;
  void vertexJacobians(const SceneState& current, const std::string& body, const std::vector<std::uint32_t>& vertices,
                       DoubleView q, VertexJacobiansAnswer& answer) const
  {
    vertexJacobians(current, body, vertices, q, answer.positions, answer.jacobians);
  }

  /// The reduced transport of vertexJacobians (~get_vertex_jacobians_compact):
  /// positions (3 per vertex) and, unless `positions_only`, J without the
  /// columns that are always I3 (JacobianColumns::compact), stored as Out:
  /// double, or float for the float32 transport. compactColumns(body) values
  /// per row: 3 for a free object (dp/d(phi, theta, psi)), d - 3 for a tree
  /// with a free root, d for a fixed base. The checks and messages of
  /// vertexJacobians, with max(Out) as the overflow limit. Instantiated for
  /// Out = double and float.
  template <typename Out>
  void vertexRotationJacobians(const SceneState& current, const std::string& body,
                               const std::vector<std::uint32_t>& vertices, DoubleView q,
                               bool positions_only, std::vector<Out>& positions,
                               std::vector<Out>& rotation_jacobians) const;

  /// vertexRotationJacobians into the float32 fields of `answer` when
  /// `single_precision`, else into its float64 fields (~get_vertex_jacobians_compact).
  void vertexJacobiansCompact(const SceneState& current, const std::string& body,
                              const std::vector<std::uint32_t>& vertices, DoubleView q, bool positions_only,
                              bool single_precision, VertexJacobiansCompactAnswer& answer) const;

  /// What each body of the scene is (BodiesAnswer), the same for every state (~get_bodies).
  void bodies(const SceneState& current, BodiesAnswer& answer) const;

  /// dL/dx = sum_i J_i^T g_i at each of the K configurations of `q` (d K
  /// values; empty = the current state, K = 1), for gradients g given as
  /// K x N x 3 values (configuration-major: 3 per selected vertex for each
  /// configuration), into `gradient` (K x d values, configuration k's as a
  /// call with its x and gradients alone would give them, same bits; its
  /// buffer is reused, and it is left empty on refusal).
  void backpropConfigurations(const SceneState& current, const std::string& body,
                              const std::vector<std::uint32_t>& vertices, DoubleView gradients,
                              DoubleView q, std::vector<double>& gradient) const;
  void backpropConfigurations(const SceneState& current, const std::string& body,
                              const std::vector<std::uint32_t>& vertices, DoubleView gradients, DoubleView q,
                              BackpropAnswer& answer) const
  {
    backpropConfigurations(current, body, vertices, gradients, q, answer.gradient);
  }
  std::vector<double> backpropConfigurations(const SceneState& current, const std::string& body,
                                             const std::vector<std::uint32_t>& vertices,
                                             DoubleView gradients,
                                             DoubleView q) const;

  /// Columns per row of body `index`'s compact Jacobian (see vertexRotationJacobians).
  std::size_t compactColumns(std::size_t index) const { return compact_columns_[index].width; }

  /// backpropConfigurations for one configuration (`q` empty or d values).
  Eigen::VectorXd backprop(const SceneState& current, const std::string& body,
                           const std::vector<std::uint32_t>& vertices, DoubleView gradients,
                           DoubleView q) const;

  /// Inverse dynamics of the bodies `bodies` (empty = all) at K
  /// configurations (q: K D values, D the sum of their d; empty = the
  /// current state, K = 1), with qdot and qddot of q's length or empty
  /// (zeros): tau, c and g, and with `coriolis_matrices` C, with `derivatives`
  /// dtau/dx and dtau/dx' (rnea.h, rnea_derivatives.h). Defined everywhere,
  /// gimbal lock included. Refused, before anything is computed: unknown
  /// bodies, lengths that do not match, non-finite values, answers over
  /// RequestLimits' budgets; after: a result that is not finite.
  void inverseDynamics(const SceneState& current, const std::vector<std::string>& bodies,
                       DoubleView q, DoubleView qdot,
                       DoubleView qddot, bool coriolis_matrices, bool derivatives,
                       InverseDynamicsAnswer& answer) const;

  /// Forward dynamics x'' (forward_dynamics.h), with `derivatives`
  /// dx''/dx, dx''/dx' and M^-1, laid out and checked as inverseDynamics
  /// (tau in place of qddot). A configuration where M is singular refuses the
  /// whole request, naming the body, the configuration and why.
  void forwardDynamics(const SceneState& current, const std::vector<std::string>& bodies,
                       DoubleView q, DoubleView qdot, DoubleView tau,
                       bool derivatives, ForwardDynamicsAnswer& answer) const;

  /// Poses, Jacobians (in `reference`: 0 WORLD, 1 LOCAL, 2
  /// LOCAL_WORLD_ALIGNED; frame_jacobians.h) and, when `acceleration_bias`,
  /// the classical acceleration biases of the link frames `frames` of
  /// `body` (empty = every link of the body, in model.links order; a static
  /// link or the fixed frame, by its URDF name: fixed pose, zero columns and
  /// bias), at K configurations (q: K d values; empty = the current state)
  /// with qdot of q's length or empty (zeros). Without the bias only the
  /// listed frames' paths are placed (forwardKinematicsOf). Refused, before
  /// anything is computed: an unknown body or frame (naming it and the known
  /// ones), an unknown reference, lengths that do not match, non-finite
  /// values, an answer over RequestLimits::kMaxMassMatrixDoublesWithDerivatives;
  /// after: a result that is not finite.
  void frameJacobians(const SceneState& current, const std::string& body, const std::vector<std::string>& frames,
                      DoubleView q, DoubleView qdot, std::uint32_t reference,
                      bool acceleration_bias, FrameJacobianAnswer& answer) const;

  /// Centre of mass of the bodies `bodies` (empty = all), and with
  /// `jacobians` its Jacobian and acceleration bias, laid out and checked as
  /// inverseDynamics (qdot in place of qddot); a massless body is refused.
  void centerOfMass(const SceneState& current, const std::vector<std::string>& bodies, DoubleView q,
                    DoubleView qdot, bool jacobians, CenterOfMassAnswer& answer) const;

  /// This thread's workspace for body `index`, made on first use and kept
  /// for the thread's next calls on this SceneQueries: queries allocate
  /// nothing for their computation in steady state, and threads share none.
  BodyWorkspace<double>& workspace(std::size_t index) const;

private:
  /// K for a request's `q` (empty = 1, else its size / d), checked against
  /// its size (a multiple of d = dofs(index)), the vertex limit for K x
  /// `vertex_count`, and the answer limit for `width` columns.
  std::size_t configurationCount(DoubleView q, std::size_t index, std::size_t vertex_count,
                                 std::size_t width) const;
  /// The d values of configuration k of body `index`: q + d k, or the current state when `q` is empty.
  const double* configurationQ(const SceneState& current, std::size_t index, DoubleView q,
                               std::size_t k) const;
  /// Checks every index of `vertices` against body `index`.
  std::size_t checkVertices(std::size_t index, const std::vector<std::uint32_t>& vertices) const;
  /// Refuses, naming the configuration when there are several, a
  /// configuration whose vertexOutputBound exceeds `limit`.
  void checkOutputsFit(const SceneState& current, std::size_t index, const JacobianColumns& columns,
                       const std::vector<std::uint32_t>& vertices, DoubleView q,
                       std::size_t configurations, double limit, const char* suffix) const;
  /// The vertex query behind vertexJacobians and vertexRotationJacobians.
  template <typename Out>
  void vertexQuery(const SceneState& current, const std::string& body, const std::vector<std::uint32_t>& vertices,
                   DoubleView q, bool compact, bool positions_only, std::vector<Out>& positions,
                   std::vector<Out>& jacobians) const;
  /// Refuses a get_mass_matrix answer over the budget of doubles.
  void checkMassMatrixBudget(std::size_t configurations, std::size_t bodies, std::size_t per_configuration,
                             bool all_six, bool derivatives, std::size_t q_size) const;

  Scene scene_;
  Eigen::Vector3d gravity_;
  /// Per body: every Jacobian column, and the compact transport's.
  std::vector<JacobianColumns> all_columns_;
  std::vector<JacobianColumns> compact_columns_;
  /// Body name -> index: O(1) lookups, so that a request of 10^5 states on a
  /// scene of 10^5 bodies is not quadratic.
  std::unordered_map<std::string, std::size_t> body_index_;
  /// Independent joint name -> (body, x index), and the names of mimic joints.
  std::unordered_map<std::string, std::pair<std::size_t, std::size_t>> joint_index_;
  std::unordered_set<std::string> mimic_joints_;
  /// Link name -> (body, index in its links), for frame requests.
  std::unordered_map<std::string, std::pair<std::size_t, std::size_t>> link_index_;
  /// Tells this object's workspaces from another's in a thread's cache (never reused).
  std::uint64_t id_;
};

/// Throws InvalidArgumentError("<field>[<i>]: not finite (...)") for the first
/// non-finite value.
void requireFinite(const double* values, std::size_t count, const char* field);

}  // namespace diff_rigid_body
