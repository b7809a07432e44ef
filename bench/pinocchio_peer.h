// Pinocchio 3.7.0 (bench/third_party/pinocchio) behind a narrow API: a peer
// for the benchmarks and an oracle for the unit tests. Library
// drb_pinocchio_peer (CMakeLists.txt); never linked into the node or the core.
//
// This header includes neither Pinocchio nor boost (pimpl): including it
// costs what Eigen costs. Each algorithm lives in its own translation unit of
// bench/pinocchio_peer/ so that they compile in parallel (see the vendored
// README for why: one TU holding them all takes minutes).
//
// Units: SI (m, rad, kg, kg m^2, N, N m, s). Vectors and matrices are in
// Pinocchio's coordinate order (see PinocchioRobot::joints()): configuration
// q (size nq()), velocity, acceleration and generalized force (size nv()).
//
// Results are references into the robot's own storage (Pinocchio's Data,
// allocated once in the constructor): valid until the next call of any
// member function that computes, and overwritten by it. Copy a result before
// calling again when two results are compared
// (`Eigen::VectorXd tau0 = robot.rnea(q, v, a);`), or a difference of two
// calls is silently zero. Not thread-safe: one robot per thread.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace drb_pinocchio
{

/// What carries the robot's root.
enum class PinocchioRoot
{
  /// The URDF as Pinocchio reads it: its root link fixed in the world. A URDF
  /// `floating` joint becomes Pinocchio's JointModelFreeFlyer (as in FreeFlyer).
  Fixed,
  /// Pinocchio's own JointModelFreeFlyer above the URDF's root link (as
  /// Pinocchio's benchmark/timings.cpp does): position of the root link's
  /// origin then a unit quaternion (x, y, z, w), nq = nv + 1, velocities in
  /// the root link's frame. Not this project's free body: use it for timing
  /// rows only, never as an oracle of the project's M.
  FreeFlyer,
  /// The oracle free body (vendored README): a JointModelTranslation, then
  /// JointModelRZ (psi), JointModelRY (theta), JointModelRX (phi), identity
  /// rotations, so R = Rz(psi) Ry(theta) Rx(phi) with Euler-angle rates as
  /// velocities. Coordinates (tx, ty, tz, psi, theta, phi), nq = nv.
  ///
  /// As in this project (docs/derivation.md), (tx, ty, tz) is the world
  /// position of the floating segment's COM, not its link origin: the chain
  /// is placed at the COM of the floating link plus every link fixed to it
  /// (FloatingBody::com_offset = c, in the link frame), and the link origin
  /// is at t - R c. The project's q = (phi, theta, psi, tx, ty, tz) is then
  /// a pure permutation of Pinocchio's: with P the 6x6 permutation
  /// q_pinocchio = P q_project, M_project = P^T M_pinocchio P (the same for
  /// every algorithm: no velocity map, no dP/dt).
  ///
  /// Which link floats: if the URDF has `floating` joints, each of them
  /// becomes such a chain (its child link floats; the URDF's origin of the
  /// floating joint is ignored, as the project treats it as the initial
  /// state, so the chain's coordinates are relative to the parent link's
  /// frame, i.e. world coordinates under a fixed root). Otherwise one chain
  /// is added above the URDF's root link, which floats.
  ///
  /// Do not use Pinocchio's JointModelSphericalZYX instead: its Coriolis
  /// matrix and derivatives are wrong in 3.7.0 (vendored README).
  EulerZYX,
};

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// Columns of spatial vectors, Pinocchio's layout: rows 0-2 linear, 3-5 angular.
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// One Pinocchio joint (the universe excluded), in Pinocchio's order
/// (depth first from the URDF's root, parents before children).
struct JointInfo
{
  std::string name;  ///< the URDF joint's name; EulerZYX chains: <floating joint or "root_joint">_{translation,rz,ry,rx}
  std::string type;  ///< Pinocchio's shortname(): JointModelRZ, JointModelPrismaticUnaligned, JointModelRUBX (continuous), ...
  int id = 0;        ///< Pinocchio's JointIndex (1 .. number of joints)
  int parent = 0;    ///< parent JointIndex (0: the universe)
  int idx_q = 0, nq = 0;  ///< slice of q
  int idx_v = 0, nv = 0;  ///< slice of v, a, tau and of the rows/columns of M
  /// URDF <mimic> of this joint: the master joint's name (empty if none),
  /// multiplier and offset. Pinocchio ignores <mimic> here (buildModel's
  /// default, mimic = false): a mimic joint is an independent dof. To get a
  /// model whose coordinate c drives joint j by multiplier A(j, c), map
  /// M' = A^T M A, tau' = A^T tau (and q_j = A(j, c) x_c + offset_j).
  /// (Pinocchio's mimic = true is not used: 3.7.0 replaces a mimic axis that
  /// is not +x, +y or +z by +x, e.g. the Panda's right finger.)
  std::string mimic;
  double multiplier = 1.0, offset = 0.0;
};

/// A floating segment of an EulerZYX robot.
struct FloatingBody
{
  std::string link;  ///< the floating link (the URDF's root link, or a `floating` joint's child)
  int idx_q = 0;     ///< its (tx, ty, tz, psi, theta, phi) are q.segment(idx_q, 6) (idx_v: the same)
  /// c: the COM of the link and every link fixed to it, in the link frame [m].
  /// (tx, ty, tz) = link origin + R c.
  Eigen::Vector3d com_offset = Eigen::Vector3d::Zero();
};

/// dtau/dq, dtau/dv and M from rneaDerivatives().
struct RneaDerivatives
{
  const RowMatrixXd& dtau_dq;  ///< nv x nv
  const RowMatrixXd& dtau_dv;  ///< nv x nv
  const Eigen::MatrixXd& M;    ///< nv x nv, symmetric, full (the same object as crba()'s result)
};

/// ddq/dq, ddq/dv and M^-1 from abaDerivatives().
struct AbaDerivatives
{
  const RowMatrixXd& ddq_dq;  ///< nv x nv
  const RowMatrixXd& ddq_dv;  ///< nv x nv
  const RowMatrixXd& Minv;    ///< nv x nv, symmetric, full (= ddq/dtau)
};

/// A link frame's Jacobian and classical acceleration from frameJacobian().
struct FrameJacobian
{
  const Matrix6Xd& J;                   ///< 6 x nv, rows linear then angular, in the requested reference
  Eigen::Matrix<double, 6, 1> classical;  ///< getFrameClassicalAcceleration at a = 0, same reference
};

/// The centre of mass from centerOfMass().
struct CenterOfMass
{
  Eigen::Vector3d com;          ///< world [m]
  const Eigen::Matrix3Xd& J;    ///< 3 x nv (jacobianCenterOfMass)
  Eigen::Vector3d acceleration;  ///< at a = 0 [m/s^2]
};

/// A URDF loaded by Pinocchio, with its Data.
class PinocchioRobot
{
public:
  /// Loads `urdf_file` (meshes are not read). Throws std::invalid_argument
  /// (or what Pinocchio or urdfdom throw) if it cannot be loaded.
  explicit PinocchioRobot(const std::string& urdf_file, PinocchioRoot root = PinocchioRoot::Fixed);
  ~PinocchioRobot();
  PinocchioRobot(PinocchioRobot&&) noexcept;
  PinocchioRobot& operator=(PinocchioRobot&&) noexcept;
  PinocchioRobot(const PinocchioRobot&) = delete;
  PinocchioRobot& operator=(const PinocchioRobot&) = delete;

  int nq() const;
  int nv() const;
  PinocchioRoot root() const;
  /// Every joint, in Pinocchio's order; the URDF's 1-dof joints have nv = 1
  /// (nq = 1, except continuous joints: nq = 2, (cos, sin)). Permute to
  /// another coordinate order by name: x_k = q[joints()[j].idx_q] etc.
  const std::vector<JointInfo>& joints() const;
  /// idx_v of the joint named `name`, -1 if there is none.
  int velocityIndex(const std::string& name) const;
  /// The floating segments (EulerZYX only; empty for Fixed and FreeFlyer).
  const std::vector<FloatingBody>& floatingBodies() const;

  /// Pinocchio's neutral configuration (zeros; identity quaternion; (1, 0) for continuous joints).
  Eigen::VectorXd neutral() const;
  /// q (size nq) from one value per velocity coordinate x (size nv, Pinocchio's
  /// order): x copied where nq = nv; a continuous joint's angle a gives
  /// (cos a, sin a); a free flyer's six values (tx, ty, tz, phi, theta, psi)
  /// give (tx, ty, tz) and the quaternion of Rz(psi) Ry(theta) Rx(phi).
  Eigen::VectorXd configuration(const Eigen::VectorXd& x) const;

  /// Gravity acceleration in the world frame [m/s^2], default (0, 0, -9.81).
  void setGravity(const Eigen::Vector3d& g);
  Eigen::Vector3d gravity() const;

  /// M(q) [kg, kg m, kg m^2], nv x nv, symmetric with both triangles filled
  /// (Pinocchio's crba fills the upper one; the copy to the lower one is
  /// inside this call, so inside any timing of it).
  const Eigen::MatrixXd& crba(const Eigen::VectorXd& q);

  /// Joint placements (Pinocchio's forwardKinematics, position level).
  void forwardKinematics(const Eigen::VectorXd& q);
  /// World pose of joint `id` (JointInfo::id) after the last forwardKinematics (or any
  /// algorithm that computes placements: crba, rnea, jacobians, ...).
  Eigen::Isometry3d jointPose(int id) const;
  /// World pose of the URDF link `link` (its frame, not its COM) from the same
  /// placements. Throws std::invalid_argument for an unknown link.
  Eigen::Isometry3d linkPose(const std::string& link) const;

  /// Pinocchio's data.J, 6 x nv: column k is the spatial velocity of the
  /// body moved by coordinate k for a unit rate, in world axes at the world
  /// origin (rows 0-2: the velocity v0 of the material point at the world
  /// origin, rows 3-5: the angular velocity w). A point p of that body moves
  /// at v0 + w x p, so its 3 x nv Jacobian is J_lin - [p]_x J_ang over the
  /// columns of the joints that support it (the others must be zeroed).
  const Matrix6Xd& computeJointJacobians(const Eigen::VectorXd& q);

  /// The frame of URDF link `link`: computeFrameJacobian in `reference` (0
  /// WORLD, 1 LOCAL, 2 LOCAL_WORLD_ALIGNED) and getFrameClassicalAcceleration
  /// at (q, v, a = 0). Throws std::invalid_argument for an unknown link.
  FrameJacobian frameJacobian(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const std::string& link,
                              int reference);
  /// The centre of mass of the subtree below the joint named `joint`, its
  /// Jacobian (jacobianSubtreeCenterOfMass) and its acceleration at
  /// (q, v, a = 0) (centerOfMass's subtree values). Throws
  /// std::invalid_argument for an unknown joint.
  CenterOfMass centerOfMass(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const std::string& joint);
  /// The frame index of URDF link `link` (throws std::invalid_argument for an unknown link).
  std::size_t frameOf(const std::string& link) const;
  /// computeFrameJacobian of frame `frame` (frameOf) in `reference` alone: what a per-frame
  /// Jacobian costs in Pinocchio (the supporting joints' placements included).
  const Matrix6Xd& computeFrameJacobian(const Eigen::VectorXd& q, std::size_t frame, int reference);
  /// jacobianCenterOfMass of the whole model (its COM and 3 x nv Jacobian).
  const Eigen::Matrix3Xd& jacobianCenterOfMass(const Eigen::VectorXd& q);

  /// Inverse dynamics tau = M(q) a + C(q, v) v + g(q) [N, N m].
  const Eigen::VectorXd& rnea(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a);
  /// g(q) = rnea(q, 0, 0) [N, N m].
  const Eigen::VectorXd& generalizedGravity(const Eigen::VectorXd& q);
  /// C(q, v) with C v = rnea(q, v, 0) - g(q) (Pinocchio's computeCoriolisMatrix), nv x nv.
  const Eigen::MatrixXd& coriolisMatrix(const Eigen::VectorXd& q, const Eigen::VectorXd& v);
  /// Partial derivatives of rnea (computeRNEADerivatives); M as a by-product.
  /// For a continuous joint (nq = 2) dq means the tangent (angle) direction.
  RneaDerivatives rneaDerivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a);

  /// Forward dynamics ddq = M^-1 (tau - C v - g) (articulated-body algorithm).
  const Eigen::VectorXd& aba(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& tau);
  /// Partial derivatives of aba (computeABADerivatives) and M^-1.
  AbaDerivatives abaDerivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& tau);

  struct Impl;  ///< Pinocchio's Model and Data (bench/pinocchio_peer/impl.h)

private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace drb_pinocchio
