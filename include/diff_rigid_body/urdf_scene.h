// A scene of free rigid bodies built from a URDF description (urdfdom).
//
// Semantics (see the package's interface contract):
//   - A body is the child link of a `floating` joint. The child of a
//     `revolute`, `continuous`, `prismatic` or `planar` joint is also a free
//     body (maximal coordinates, initial pose at joint value 0); such joints
//     are listed in Scene::unmodelled_joints.
//   - Links joined to a body by `fixed` joints, directly or transitively, are
//     merged into it: composite mass, COM and inertia, vertices appended.
//   - Links fixed to the root are static: no state, published once.
//   - Vertices are the unique positions of the body's geometry in the body
//     frame (origin at the COM, link axes): the body's own link first, then
//     merged links in document order; within a link, geometry elements in
//     order, then mesh order.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

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

struct SceneOptions
{
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

/// A link merged into a body, with its fixed pose relative to the body's link frame.
struct LinkInBody
{
  std::string name;
  Eigen::Isometry3d pose_in_body_link = Eigen::Isometry3d::Identity();
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
  RigidBody body;
  /// q = (phi, theta, psi, tx, ty, tz) from the URDF joint origins.
  Vector6<double> initial_state = Vector6<double>::Zero();
  /// The body's own link first, then its merged links in document order.
  std::vector<LinkInBody> links;
  /// Name of the joint that made this link a body, and its URDF type.
  std::string joint_name;
  std::string joint_type;
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
