// Where every link of a URDF sits at zero joint values and which rigid group
// of links it belongs to (internal to the core): the first step from a
// description (urdf_model.h) to bodies (body_builder.h).
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "parsers/urdf_model.h"

namespace diff_rigid_body
{
namespace detail
{
struct LinkTree
{
  /// Per link, in document order (UrdfDescription::link_order): its pose in
  /// the root link's frame with every joint at 0.
  std::vector<Eigen::Isometry3d> pose_in_root;
  /// Per link: "" for a static link (fixed to the root), else the moving
  /// link (the child of a non-fixed joint) whose rigid group it is in.
  std::vector<std::string> owner;
  /// Moving links in document order.
  std::vector<std::string> moving_links;
  /// Per moving link: the links fixed to it, in document order.
  std::unordered_map<std::string, std::vector<std::string>> merged_links;

  const Eigen::Isometry3d& pose(const UrdfDescription& description, const std::string& link) const
  {
    return pose_in_root[description.link_index.at(link)];
  }
  const std::string& ownerOf(const UrdfDescription& description, const std::string& link) const
  {
    return owner[description.link_index.at(link)];
  }
  bool isStatic(const UrdfDescription& description, const std::string& link) const
  {
    return ownerOf(description, link).empty();
  }
};

/// Walks the tree from the root with an explicit stack (a chain of 10^5
/// links must not overflow the call stack). Throws SceneDescriptionError
/// naming a joint whose <origin> is not finite.
LinkTree placeLinks(const UrdfDescription& description);

}  // namespace detail
}  // namespace diff_rigid_body
