// urdfdom glue for the scene builder (not installed): parsing with urdfdom's
// errors captured, the joint graph checked, document order, poses and joint
// names.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>
#include <urdf_world/types.h>
#include <urdf_model/model.h>

namespace diff_rigid_body
{
namespace detail
{
/// urdfdom's model of `urdf_xml`. Throws SceneDescriptionError quoting what
/// urdfdom logged: urdfdom may log an error and still return a model in
/// which the bad element is silently reset or dropped (e.g. mass="nan"
/// becomes 0, a <box size="nan 1 1"> disappears), so any logged error
/// refuses the description.
urdf::ModelInterfaceSharedPtr parseUrdfModel(const std::string& urdf_xml);

/// Names of the <robot>'s `element` children ("link" or "joint") in document
/// order (urdfdom keeps them in std::maps). Throws SceneDescriptionError for
/// malformed XML or a missing <robot>.
std::vector<std::string> namesInDocumentOrder(const std::string& urdf_xml, const char* element);

/// A URDF as the scene builder reads it: urdfdom's model, whose joints form
/// a tree (urdf_topology.h), and the document order that urdfdom's maps lose.
struct UrdfDescription
{
  urdf::ModelInterfaceSharedPtr model;
  std::vector<std::string> link_order;   ///< link names in document order
  std::vector<std::string> joint_order;  ///< joint names in document order
  std::unordered_map<std::string, std::size_t> link_index;  ///< name -> index in link_order

  const urdf::Link& link(const std::string& name) const { return *model->getLink(name); }
  const urdf::Joint& joint(const std::string& name) const { return *model->getJoint(name); }
};

/// Parses `urdf_xml` (parseUrdfModel, namesInDocumentOrder) and checks that
/// its joints form one tree (checkTreeTopology). Throws SceneDescriptionError
/// whose message starts with `source` (e.g. "robot description" or
/// "URDF file '/path/robot.urdf'"), then what is wrong and where.
UrdfDescription readUrdfDescription(const std::string& urdf_xml, const std::string& source);

/// ~floating_base: makes the root link the child of a new link `frame` through
/// a `floating` joint at the identity (named "floating_base", or
/// "floating_base_<i>" when the URDF has a joint of that name), as a
/// hand-written `<link name="frame"/>` and `<joint type="floating">` first in
/// the document would. Throws SceneDescriptionError when `frame` is already a
/// link of the description.
void addFloatingRoot(UrdfDescription& description, const std::string& frame);

/// Revolute, continuous and prismatic joints: one coordinate each.
bool movesOneCoordinate(int joint_type);

/// The pose as an isometry (quaternion normalised).
Eigen::Isometry3d toIsometry(const urdf::Pose& pose);

/// "revolute", "continuous", "prismatic", "floating", "planar", "fixed" or "unknown".
const char* jointTypeName(int type);
}  // namespace detail
}  // namespace diff_rigid_body
