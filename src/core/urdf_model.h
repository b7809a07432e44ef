// urdfdom glue for the scene builder (not installed): parsing with urdfdom's
// errors captured, link order, poses and joint names.
#pragma once

#include <string>
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

/// The pose as an isometry (quaternion normalised).
Eigen::Isometry3d toIsometry(const urdf::Pose& pose);

/// "revolute", "continuous", "prismatic", "floating", "planar", "fixed" or "unknown".
const char* jointTypeName(int type);
}  // namespace detail
}  // namespace diff_rigid_body
