// A rigid group of URDF links, a moving link and the links fixed to it: its
// composite mass properties and its vertices (internal to the core). Every
// segment of a body is one (body_builder.h).
#pragma once

#include <string>
#include <vector>

#include "diff_rigid_body/multibody/body_model.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "parsers/link_geometry.h"
#include "parsers/link_tree.h"

namespace diff_rigid_body
{
namespace detail
{
/// What loading carries from one step to the next: the options, each mesh
/// file read once, and the findings that load with a warning.
struct LoadContext
{
  explicit LoadContext(const SceneOptions& scene_options) : options(scene_options), meshes(scene_options) {}

  /// An implausible finding: a warning saying what was done about it
  /// (`consequence`), or InvalidInertiaError with ~strict_inertia.
  void implausible(const std::string& finding, const std::string& consequence);

  const SceneOptions& options;
  GeometryMeshes meshes;
  std::vector<std::string> warnings;
};

/// Where a group's vertices are measured from, and how it is warned about.
enum class GroupRole
{
  FreeObject,  ///< a body of one segment on a free root: vertices about the COM, warned about as a body
  FreeRoot,    ///< the free root of a tree: vertices about the COM
  JointSegment ///< vertices in its link frame
};

struct RigidGroup
{
  std::vector<LinkInBody> links;  ///< the moving link first, then merged links in document order
  MassProperties mass;            ///< composite, in the moving link's frame
  Matrix3X<double> vertices;      ///< unique positions, in the link frame minus the COM for a free root
};

/// The group of `link` (a moving link): every member's geometry (chosen by
/// options.geometry) and mass properties (<inertial>, else ~density and its
/// geometry, else massless with a warning), composite mass properties, and
/// the unique vertices in first-occurrence order, each link's new ones
/// contiguous. Throws for undefined inertia and unreadable geometry.
RigidGroup mergeRigidGroup(const UrdfDescription& description, const LinkTree& tree, const std::string& link,
                           GroupRole role, LoadContext& context);

}  // namespace detail
}  // namespace diff_rigid_body
