// A scene of rigid and articulated bodies built from a URDF description
// (urdfdom).
//
// Semantics (see the package's interface contract, "Version 2"):
//   - JointHandling::Model (default): a body is a kinematic tree
//     (body_model.h). Its root is the child of a `floating` joint (a free
//     root), or a link joined to a static link by a revolute, continuous or
//     prismatic joint (a fixed-base root); the links below it through fixed
//     and 1-dof joints belong to it. A `floating` joint below a moving link
//     starts a new body; a `planar` joint makes its child a free root
//     (listed in Scene::unmodelled_joints). A free root with no joints below
//     it is a free object, as a version-1 body.
//   - JointHandling::Free (version 1): the child of every `floating`,
//     `revolute`, `continuous`, `prismatic` or `planar` joint is a free body
//     (maximal coordinates, initial pose at joint value 0); the 1-dof and
//     planar joints are listed in Scene::unmodelled_joints.
//   - Links joined to a body by `fixed` joints, directly or transitively, are
//     merged into it: composite mass, COM and inertia, vertices appended.
//   - Links fixed to the root are static: no state, published once.
//   - SceneOptions::floating_base: the root link first becomes the child of
//     a `floating` joint from a new fixed frame (SceneOptions::fixed_frame,
//     default "world"), so it and the links below it form one free-rooted body.
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

#include "diff_rigid_body/multibody/body_model.h"

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
  /// fixed to it. Empty means the root link. With floating_base: the name of
  /// the new frame above the root link, not a link of the URDF; empty means
  /// "world".
  std::string fixed_frame;
  /// ~floating_base: the URDF's root link is a free root with the six
  /// Euler-angle coordinates q = (phi, theta, psi, tx, ty, tz) (t the COM of
  /// the root link's merged group, in the fixed frame), exactly as if a
  /// `floating` joint joined it to the fixed frame (for legged and mobile
  /// robots, whose URDF's root has no parent joint).
  bool floating_base = false;
  /// Resolves `package://pkg/path` to a file path; throws or returns "" when
  /// the package is unknown. `file://` URIs and absolute paths need no resolver.
  std::function<std::string(const std::string& package)> find_package;
  /// Folder that relative mesh paths are taken from (e.g. the URDF file's).
  std::string base_directory;
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
  std::vector<BodyModel> bodies;
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

}  // namespace diff_rigid_body
