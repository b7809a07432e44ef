// A scene of rigid and articulated bodies built from a URDF description
// (urdfdom).
//
// Semantics (see the package's interface contract, "Version 2"):
//   - JointHandling::Model (default): a body is a kinematic tree
//     (articulated_body.h). Its root is the child of a `floating` joint, or a
//     link joined to a static link by a revolute, continuous or prismatic
//     joint; the links below it through fixed and 1-dof joints belong to it.
//     A `floating` joint below a moving link starts a new body; a `planar`
//     joint makes its child a free body (listed in Scene::unmodelled_joints).
//     A body with a floating root and no joints is a free body as in
//     version 1 (SceneBody::articulated is null).
//   - JointHandling::Free (version 1): the child of every `floating`,
//     `revolute`, `continuous`, `prismatic` or `planar` joint is a free body
//     (maximal coordinates, initial pose at joint value 0); the 1-dof and
//     planar joints are listed in Scene::unmodelled_joints.
//   - Links joined to a body by `fixed` joints, directly or transitively, are
//     merged into it: composite mass, COM and inertia, vertices appended.
//   - Links fixed to the root are static: no state, published once.
//   - Vertices are the unique positions of the body's geometry in the body
//     frame (origin at the COM, link axes): the body's own link first, then
//     merged links in document order; within a link, geometry elements in
//     order, then mesh order.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "diff_rigid_body/articulated_body.h"
#include "diff_rigid_body/rigid_body.h"

namespace diff_rigid_body
{
/// Which URDF geometry supplies the vertices; the other is used for a link
/// that has none of the chosen kind.
enum class GeometrySource
{
  Collision,
  Visual
};

/// How 1-dof joints are treated (~joints).
enum class JointHandling
{
  Model,  ///< bodies are kinematic trees with joint coordinates
  Free    ///< version 1: every moving link is a free body
};

struct SceneOptions
{
  JointHandling joints = JointHandling::Model;
  GeometrySource geometry = GeometrySource::Collision;
  /// [kg/m^3] When set, a link without <inertial> gets its mass properties
  /// from its closed geometry. When unset, such a link is merged as massless
  /// (with a warning).
  std::optional<double> density;
  /// When false (default), implausible inertia loads with a warning naming the
  /// link (zero mass, no <inertial>, a zero principal moment, the triangle
  /// inequality broken, a body whose coordinates move no mass); when true,
  /// each of these is refused with InvalidInertiaError. Undefined inertia
  /// (negative or non-finite mass or principal moment) is always refused.
  bool strict_inertia = false;
  /// Names of the bodies to model; empty means all. Meshes of other bodies
  /// are never read. An unknown name is a load error.
  std::vector<std::string> bodies;
  /// Frame that states and poses are expressed in: the root link or a link
  /// fixed to it. Empty means the root link.
  std::string fixed_frame;
  /// Resolves `package://pkg/path` to a file path; throws or returns "" when
  /// the package is unknown. `file://` URIs and absolute paths need no resolver.
  std::function<std::string(const std::string& package)> find_package;
  /// Folder that relative mesh paths are taken from (e.g. the URDF file's).
  std::string base_directory;
};

/// A link of a body, with its fixed pose relative to the body's link frame
/// (for an articulated body: relative to its segment's link frame).
struct LinkInBody
{
  std::string name;
  Eigen::Isometry3d pose_in_body_link = Eigen::Isometry3d::Identity();
  /// Index of its segment in SceneBody::articulated (0 for a free body).
  std::size_t segment = 0;
  /// Indices (into RigidBody::vertices) of this link's own geometry vertices,
  /// in the link's geometry order.
  std::vector<std::uint32_t> vertex_indices;
  /// How many of the body's vertices start at this link: the links' new
  /// vertices are contiguous, in link order.
  std::uint32_t new_vertex_count = 0;
  /// The link's own mass properties, in its link frame: mass [kg], COM [m],
  /// inertia about the COM in link axes [kg m^2]. Zero for a massless link.
  MassProperties mass_properties;
};

struct SceneBody
{
  /// A free body's model. For an articulated body: its name, total mass,
  /// the root segment's inertia and COM offset, and no vertices (they are
  /// in `articulated`).
  RigidBody body;
  /// The kinematic tree of a body with joints; null for a free body.
  std::shared_ptr<const ArticulatedBody> articulated;
  /// x at load: q = (phi, theta, psi, tx, ty, tz) from the URDF joint origins
  /// for a free body or floating root, then every joint at 0.
  Eigen::VectorXd initial_state = Eigen::VectorXd::Zero(6);
  /// Free body: the body's own link first, then its merged links in document
  /// order. Articulated body: segment after segment, each its link first,
  /// then its merged links; vertex ranges follow the same order.
  std::vector<LinkInBody> links;
  /// Name of the joint that made this link a body, and its URDF type.
  std::string joint_name;
  std::string joint_type;

  /// len(x): 6 for a free body.
  std::size_t dofs() const { return articulated ? articulated->dofs() : 6; }
  /// Number of vertices.
  std::size_t vertexCount() const
  {
    return articulated ? static_cast<std::size_t>(articulated->vertices.cols()) :
                         static_cast<std::size_t>(body.vertices.cols());
  }
};

/// A link fixed to the root, with its pose in the fixed frame.
struct StaticLink
{
  std::string name;
  Eigen::Isometry3d pose_in_fixed_frame = Eigen::Isometry3d::Identity();
};

struct Scene
{
  std::string fixed_frame;
  std::vector<SceneBody> bodies;
  std::vector<StaticLink> static_links;
  /// One line per joint whose constraint is not modelled, e.g.
  /// "joint 'hinge' (revolute): child 'arm' is modelled as a free body".
  std::vector<std::string> unmodelled_joints;
  /// Implausible but loadable findings, each naming the link, joint or body:
  /// massless links, implausible inertia, a body that starts at gimbal lock.
  std::vector<std::string> warnings;
};

/// Builds the scene. Throws SceneDescriptionError (malformed XML, unknown
/// bodies or frames, no body), MeshLoadError (missing or unreadable meshes)
/// or InvalidInertiaError (invalid or missing mass properties), each naming
/// the link, joint or file at fault.
Scene loadSceneFromUrdf(const std::string& urdf_xml, const SceneOptions& options = SceneOptions());

/// Reads a URDF file and builds its scene; relative mesh paths are taken
/// from the file's folder unless options.base_directory is set.
Scene loadSceneFromUrdfFile(const std::string& path, SceneOptions options = SceneOptions());

/// Pose of a body's link frame in the fixed frame at state q:
/// rotation R(phi, theta, psi), origin t - R com_offset.
Eigen::Isometry3d linkPoseFromState(const Vector6<double>& q, const Eigen::Vector3d& com_offset);

}  // namespace diff_rigid_body
