#include "diff_rigid_body/urdf_scene.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include <urdf_model/model.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/rpy.h"
#include "body_names.h"
#include "scene_builder.h"
#include "urdf_model.h"

namespace diff_rigid_body
{
namespace detail
{
Scene SceneBuilder::build()
{
  Scene scene;
  placeLinks(model_->getRoot());
  const std::string root = model_->getRoot()->name;
  scene.fixed_frame = options_.fixed_frame.empty() ? root : options_.fixed_frame;
  const auto fixed = owner_.find(scene.fixed_frame);
  if (fixed == owner_.end() || !fixed->second.empty())
    throw SceneDescriptionError("parameter fixed_frame: '" + scene.fixed_frame + "' is not the root link '" + root +
                                "' or a link fixed to it");
  const Eigen::Isometry3d fixed_from_root = pose_in_root_.at(scene.fixed_frame).inverse();

  std::vector<std::string> moving_links;
  for (const std::string& name : document_order_)
  {
    link_document_index_.emplace(name, link_document_index_.size());
    const std::string& owner = owner_.at(name);
    if (owner.empty())
    {
      if (name != scene.fixed_frame)
        scene.static_links.push_back({ name, fixed_from_root * pose_in_root_.at(name) });
    }
    else if (owner == name)
      moving_links.push_back(name);
    else
      merged_links_[owner].push_back(name);  // one pass: loading stays linear in the links
  }
  if (moving_links.empty())
    throw SceneDescriptionError("robot description: no body (no link is the child of a floating, revolute, "
                                "continuous, prismatic or planar joint)");
  const std::vector<std::string> body_links = bodyRoots(moving_links);

  std::set<std::string> selected(options_.bodies.begin(), options_.bodies.end());
  for (const std::string& name : options_.bodies)
  {
    if (std::find(body_links.begin(), body_links.end(), name) == body_links.end())
      throw SceneDescriptionError("parameter bodies: unknown body '" + name +
                                  "' (bodies: " + formatBodyNames(body_links) + ")");
  }

  for (const std::string& name : body_links)
  {
    if (!selected.empty() && !selected.count(name))
      continue;
    const urdf::JointConstSharedPtr& joint = model_->getLink(name)->parent_joint;
    const bool free_body = options_.joints == JointHandling::Free ||
                           (!movesOneCoordinate(joint->type) && treeSegments(name).size() == 1);
    scene.bodies.push_back(free_body ? buildFreeBody(name, fixed_from_root) :
                                       buildArticulatedBody(name, fixed_from_root));
    if (joint->type == urdf::Joint::PLANAR || (options_.joints == JointHandling::Free && movesOneCoordinate(joint->type)))
      scene.unmodelled_joints.push_back("joint '" + joint->name + "' (" + jointTypeName(joint->type) +
                                        "): its constraint is not modelled; child '" + name +
                                        "' is a free body posed at joint value 0");
  }
  scene.warnings = std::move(warnings_);
  return scene;
}

// The links that start a body, in document order: with JointHandling::Free
// every moving link; with Model the children of floating and planar joints
// and the moving links joined to a static link.
std::vector<std::string> SceneBuilder::bodyRoots(const std::vector<std::string>& moving_links) const
{
  if (options_.joints == JointHandling::Free)
    return moving_links;
  std::vector<std::string> roots;
  for (const std::string& name : moving_links)
    if (isBodyRoot(name))
      roots.push_back(name);
  return roots;
}

bool SceneBuilder::isBodyRoot(const std::string& link_name) const
{
  const urdf::JointConstSharedPtr& joint = model_->getLink(link_name)->parent_joint;
  return !movesOneCoordinate(joint->type) || owner_.at(joint->parent_link_name).empty();
}

SceneBody SceneBuilder::buildFreeBody(const std::string& body_name, const Eigen::Isometry3d& fixed_from_root)
{
  SceneBody scene_body;
  const urdf::JointConstSharedPtr& joint = model_->getLink(body_name)->parent_joint;
  scene_body.joint_name = joint->name;
  scene_body.joint_type = jointTypeName(joint->type);
  RigidGroup group = buildRigidGroup(body_name, true);
  scene_body.body.name = body_name;
  scene_body.body.mass = group.mass.mass;
  scene_body.body.com_offset = group.mass.com;
  scene_body.body.inertia_body = group.mass.inertia;
  scene_body.body.vertices = std::move(group.vertices);
  scene_body.links = std::move(group.links);

  // Initial state: link axes' RPY and COM position, in the fixed frame.
  const Eigen::Isometry3d body_in_fixed = fixed_from_root * pose_in_root_.at(body_name);
  scene_body.initial_state = Eigen::VectorXd(6);
  scene_body.initial_state.head<3>() = matrixToRpy(body_in_fixed.linear());
  scene_body.initial_state.tail<3>() = body_in_fixed * group.mass.com;
  if (!scene_body.initial_state.allFinite())
    throw SceneDescriptionError("body '" + body_name +
                                "': initial state is not finite (its joint origins and COM offset add up "
                                "beyond the range of double)");
  warnIfGimbalLocked(body_name, scene_body.joint_name, scene_body.joint_type, scene_body.initial_state[1]);
  return scene_body;
}

}  // namespace detail

Scene loadSceneFromUrdf(const std::string& urdf_xml, const SceneOptions& options)
{
  return detail::SceneBuilder(urdf_xml, options).build();
}

Scene loadSceneFromUrdfFile(const std::string& path, SceneOptions options)
{
  std::ifstream file(path);
  if (!file)
    throw SceneDescriptionError("URDF file '" + path + "': cannot be opened");
  std::stringstream text;
  text << file.rdbuf();
  if (options.base_directory.empty())
  {
    const std::size_t slash = path.find_last_of('/');
    options.base_directory = slash == std::string::npos ? "." : path.substr(0, slash);
  }
  return loadSceneFromUrdf(text.str(), options);
}

Eigen::Isometry3d linkPoseFromState(const Vector6<double>& q, const Eigen::Vector3d& com_offset)
{
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rpyToMatrix(RpyTrig<double>(q));
  pose.translation() = q.tail<3>() - pose.linear() * com_offset;
  return pose;
}

}  // namespace diff_rigid_body
