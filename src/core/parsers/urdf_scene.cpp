// URDF to scene, as pure steps with explicit inputs: read the description
// (urdf_model.h: parse, check the joint graph), place its links
// (link_tree.h), choose the links that start bodies, and build each body
// (body_builder.h, rigid_group.h, body_coordinates.h).
#include "diff_rigid_body/parsers/urdf_scene.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "diff_rigid_body/exceptions.h"
#include "parsers/body_builder.h"
#include "services/body_names.h"
#include "parsers/link_tree.h"
#include "parsers/rigid_group.h"
#include "parsers/urdf_model.h"

namespace diff_rigid_body
{
namespace
{
using detail::LinkTree;
using detail::UrdfDescription;

// With JointHandling::Free every moving link starts a body; with Model the
// children of floating and planar joints and the moving links joined to a
// static link do.
std::vector<std::string> bodyRoots(const UrdfDescription& description, const LinkTree& tree,
                                   const SceneOptions& options)
{
  if (options.joints == JointHandling::Free)
    return tree.moving_links;
  std::vector<std::string> roots;
  for (const std::string& name : tree.moving_links)
  {
    const urdf::Joint& joint = *description.link(name).parent_joint;
    if (!detail::movesOneCoordinate(joint.type) || tree.isStatic(description, joint.parent_link_name))
      roots.push_back(name);
  }
  return roots;
}

// The fixed frame (the root link or a link fixed to it) and its pose.
Eigen::Isometry3d fixedFromRoot(const UrdfDescription& description, const LinkTree& tree, Scene& scene,
                                const SceneOptions& options)
{
  const std::string root = description.model->getRoot()->name;
  scene.fixed_frame = options.fixed_frame.empty() ? root : options.fixed_frame;
  const auto fixed = description.link_index.find(scene.fixed_frame);
  if (fixed == description.link_index.end() || !tree.owner[fixed->second].empty())
    throw SceneDescriptionError("parameter fixed_frame: '" + scene.fixed_frame + "' is not the root link '" + root +
                                "' or a link fixed to it");
  return tree.pose_in_root[fixed->second].inverse();
}

// Checks options.bodies against `roots` and returns the roots to model.
std::vector<std::string> selectedRoots(const std::vector<std::string>& roots, const SceneOptions& options)
{
  for (const std::string& name : options.bodies)
    if (std::find(roots.begin(), roots.end(), name) == roots.end())
      throw SceneDescriptionError("parameter bodies: unknown body '" + name +
                                  "' (bodies: " + detail::formatBodyNames(roots) + ")");
  if (options.bodies.empty())
    return roots;
  const std::set<std::string> selected(options.bodies.begin(), options.bodies.end());
  std::vector<std::string> kept;
  for (const std::string& name : roots)
    if (selected.count(name))
      kept.push_back(name);
  return kept;
}

void addBody(const UrdfDescription& description, const LinkTree& tree, const std::string& name,
             const Eigen::Isometry3d& fixed_from_root, detail::LoadContext& context, Scene& scene)
{
  const urdf::Joint& joint = *description.link(name).parent_joint;
  const bool model_joints = context.options.joints == JointHandling::Model;
  const detail::RootKind kind = model_joints && detail::movesOneCoordinate(joint.type) ?
                                    detail::RootKind::FixedBase :
                                    detail::RootKind::Free;
  scene.bodies.push_back(detail::buildBodyModel(description, tree, name, kind, model_joints, fixed_from_root, context));
  if (joint.type == urdf::Joint::PLANAR || (!model_joints && detail::movesOneCoordinate(joint.type)))
    scene.unmodelled_joints.push_back("joint '" + joint.name + "' (" + detail::jointTypeName(joint.type) +
                                      "): its constraint is not modelled; child '" + name +
                                      "' is a free body posed at joint value 0");
}
}  // namespace

namespace
{
// `source` names the description in error messages: "robot description" or "URDF file '<path>'".
Scene loadScene(const std::string& urdf_xml, const SceneOptions& options, const std::string& source)
{
  UrdfDescription description = detail::readUrdfDescription(urdf_xml, source);
  if (options.floating_base)
    detail::addFloatingRoot(description, options.fixed_frame.empty() ? "world" : options.fixed_frame);
  if (options.density && !(std::isfinite(*options.density) && *options.density > 0.0))
  {
    std::ostringstream why;
    why << "parameter density: must be finite and > 0 kg/m^3, got " << *options.density;
    throw SceneDescriptionError(why.str());
  }
  const LinkTree tree = detail::placeLinks(description);
  Scene scene;
  const Eigen::Isometry3d fixed_from_root = fixedFromRoot(description, tree, scene, options);
  for (std::size_t i = 0; i < description.link_order.size(); ++i)
    if (tree.owner[i].empty() && description.link_order[i] != scene.fixed_frame)
      scene.static_links.push_back({ description.link_order[i], fixed_from_root * tree.pose_in_root[i] });
  if (tree.moving_links.empty())
    throw SceneDescriptionError(source + ": no body (no link is the child of a floating, revolute, "
                                         "continuous, prismatic or planar joint)");
  detail::LoadContext context(options);
  for (const std::string& name : selectedRoots(bodyRoots(description, tree, options), options))
    addBody(description, tree, name, fixed_from_root, context, scene);
  scene.warnings = std::move(context.warnings);
  return scene;
}
}  // namespace

Scene loadSceneFromUrdf(const std::string& urdf_xml, const SceneOptions& options)
{
  return loadScene(urdf_xml, options, "robot description");
}

Scene loadSceneFromUrdfFile(const std::string& path, SceneOptions options)
{
  const std::string source = "URDF file '" + path + "'";
  std::error_code error;
  if (!std::filesystem::exists(path, error) && !error)
    throw SceneDescriptionError(source + ": no such file");
  std::ifstream file(path);
  if (!file)
    throw SceneDescriptionError(source + ": cannot be opened: " + std::strerror(errno));
  std::stringstream text;
  text << file.rdbuf();
  if (options.base_directory.empty())
  {
    const std::size_t slash = path.find_last_of('/');
    options.base_directory = slash == std::string::npos ? "." : path.substr(0, slash);
  }
  return loadScene(text.str(), options, source);
}

}  // namespace diff_rigid_body
