// From the links of a URDF (link_tree.h) to one BodyModel (internal to the
// core): which links are its segments, their joints, coordinates and mimic
// chains, merged mass properties and vertices, and its state at load.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "diff_rigid_body/multibody/body_model.h"
#include "parsers/link_tree.h"
#include "parsers/rigid_group.h"

namespace diff_rigid_body
{
namespace detail
{
/// How a body's root link moves.
enum class RootKind
{
  Free,      ///< six coordinates (a floating or planar joint; any moving link with JointHandling::Free)
  FixedBase  ///< a 1-dof joint below a static link
};

/// The body whose root is the moving link `root_link`. With `joints_below`,
/// its segments are every link reached from the root through fixed and 1-dof
/// joints (a floating or planar joint below starts another body); without,
/// the root's rigid group alone (JointHandling::Free). Poses are taken in
/// the fixed frame through `fixed_from_root` (the root link's frame to the
/// fixed frame). Findings go to context.warnings.
BodyModel buildBodyModel(const UrdfDescription& description, const LinkTree& tree, const std::string& root_link,
                         RootKind root_kind, bool joints_below, const Eigen::Isometry3d& fixed_from_root,
                         LoadContext& context);

}  // namespace detail
}  // namespace diff_rigid_body
