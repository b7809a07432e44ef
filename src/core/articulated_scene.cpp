// Kinematic trees for JointHandling::Model (interface.md, "Version 2").
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <sstream>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/rpy.h"
#include "scene_builder.h"
#include "urdf_model.h"

namespace diff_rigid_body
{
namespace detail
{
// The segments of the tree under `root_name` in document order of their
// links, except that a parent always comes before its children: the next
// segment is the earliest in the document among those whose parent is placed.
std::vector<std::string> SceneBuilder::treeSegments(const std::string& root_name) const
{
  using Ready = std::pair<std::size_t, std::string>;  // (document index, link)
  std::priority_queue<Ready, std::vector<Ready>, std::greater<Ready>> ready;
  ready.emplace(link_document_index_.at(root_name), root_name);
  std::vector<std::string> order;
  while (!ready.empty())
  {
    const std::string segment = ready.top().second;
    ready.pop();
    order.push_back(segment);
    // Child segments: 1-dof joints below the segment's link or its merged links.
    std::vector<urdf::LinkConstSharedPtr> rigid{ model_->getLink(segment) };
    for (std::size_t k = 0; k < rigid.size(); ++k)
      for (const urdf::JointSharedPtr& joint : rigid[k]->child_joints)
      {
        if (joint->type == urdf::Joint::FIXED)
          rigid.push_back(model_->getLink(joint->child_link_name));
        else if (movesOneCoordinate(joint->type))
          ready.emplace(link_document_index_.at(joint->child_link_name), joint->child_link_name);
      }
  }
  return order;
}

// The Segment of a 1-dof joint: its motion, unit axis, and origin in its
// parent segment's frame (or in the fixed frame below a static link).
Segment SceneBuilder::segmentJoint(const urdf::Joint& joint,
                                   const std::unordered_map<std::string, std::size_t>& segment_index,
                                   const Eigen::Isometry3d& fixed_from_root) const
{
  Segment segment;
  segment.link = joint.child_link_name;
  segment.joint = joint.name;
  segment.motion = joint.type == urdf::Joint::PRISMATIC ? JointMotion::Prismatic : JointMotion::Revolute;
  const Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
  if (!axis.allFinite() || !(axis.norm() > 0.0))
    throw SceneDescriptionError("joint '" + joint.name + "': <axis> must be a finite, non-zero vector");
  segment.axis = axis.normalized();
  const Eigen::Isometry3d origin = toIsometry(joint.parent_to_joint_origin_transform);
  const std::string& parent_segment = owner_.at(joint.parent_link_name);
  if (parent_segment.empty())
    segment.origin = fixed_from_root * pose_in_root_.at(joint.parent_link_name) * origin;
  else
  {
    segment.parent = static_cast<int>(segment_index.at(parent_segment));
    segment.origin = joint.parent_link_name == parent_segment ?
                         origin :
                         pose_in_root_.at(parent_segment).inverse() * pose_in_root_.at(joint.parent_link_name) * origin;
  }
  return segment;
}

SceneBody SceneBuilder::buildArticulatedBody(const std::string& root_name, const Eigen::Isometry3d& fixed_from_root)
{
  SceneBody scene_body;
  const urdf::JointConstSharedPtr& root_joint = model_->getLink(root_name)->parent_joint;
  scene_body.joint_name = root_joint->name;
  scene_body.joint_type = jointTypeName(root_joint->type);
  ArticulatedBody body;
  body.name = root_name;
  body.floating_root = !movesOneCoordinate(root_joint->type);

  std::unordered_map<std::string, std::size_t> segment_index;
  std::vector<Matrix3X<double>> vertex_blocks;
  std::size_t vertex_count = 0;
  for (const std::string& name : treeSegments(root_name))
  {
    const std::size_t k = body.segments.size();
    segment_index.emplace(name, k);
    Segment segment;
    if (k > 0 || !body.floating_root)
      segment = segmentJoint(*model_->getLink(name)->parent_joint, segment_index, fixed_from_root);
    segment.link = name;
    RigidGroup group = buildRigidGroup(name, false);
    segment.mass_properties = group.mass;
    segment.vertex_begin = static_cast<std::uint32_t>(vertex_count);
    segment.vertex_count = static_cast<std::uint32_t>(group.vertices.cols());
    for (LinkInBody& link : group.links)
    {
      link.segment = k;
      for (std::uint32_t& v : link.vertex_indices)
        v += segment.vertex_begin;
      scene_body.links.push_back(std::move(link));
    }
    vertex_count += static_cast<std::size_t>(group.vertices.cols());
    if (vertex_count > std::numeric_limits<std::uint32_t>::max())
      throw SceneDescriptionError("body '" + root_name + "': more than 2^32 - 1 vertices");
    vertex_blocks.push_back(std::move(group.vertices));
    body.segments.push_back(std::move(segment));
  }
  body.vertices.resize(3, static_cast<Eigen::Index>(vertex_count));
  for (std::size_t k = 0; k < body.segments.size(); ++k)
    body.vertices.middleCols(body.segments[k].vertex_begin, body.segments[k].vertex_count) = vertex_blocks[k];
  assignCoordinates(body);
  warnIfCoordinatesMoveNoMass(body);

  scene_body.body.name = root_name;
  for (const Segment& segment : body.segments)
    scene_body.body.mass += segment.mass_properties.mass;
  scene_body.body.com_offset = body.segments[0].mass_properties.com;
  scene_body.body.inertia_body = body.segments[0].mass_properties.inertia;
  scene_body.body.vertices.resize(3, 0);
  scene_body.initial_state = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(body.dofs()));
  if (body.floating_root)
  {
    const Eigen::Isometry3d root_in_fixed = fixed_from_root * pose_in_root_.at(root_name);
    scene_body.initial_state.head<3>() = matrixToRpy(root_in_fixed.linear());
    scene_body.initial_state.segment<3>(3) = root_in_fixed * body.segments[0].mass_properties.com;
    if (!scene_body.initial_state.allFinite())
      throw SceneDescriptionError("body '" + root_name + "': initial state is not finite");
    warnIfGimbalLocked(root_name, scene_body.joint_name, scene_body.joint_type, scene_body.initial_state[1]);
  }
  scene_body.articulated = std::make_shared<const ArticulatedBody>(std::move(body));
  return scene_body;
}

// Independent joints get coordinates in document order; a mimic joint
// follows its master (chains of mimics compose). A mimic whose master is not
// a 1-dof joint of the same body is modelled as independent, with a warning.
void SceneBuilder::assignCoordinates(ArticulatedBody& body)
{
  std::unordered_map<std::string, std::size_t> by_joint;
  for (std::size_t k = 0; k < body.segments.size(); ++k)
    if (!body.segments[k].joint.empty())
      by_joint.emplace(body.segments[k].joint, k);
  // Each mimic joint's master segment (null: independent).
  std::unordered_map<std::string, const Segment*> master_of;
  for (const auto& [joint, k] : by_joint)
  {
    const urdf::JointMimicSharedPtr& mimic = model_->getJoint(joint)->mimic;
    const auto master = mimic ? by_joint.find(mimic->joint_name) : by_joint.end();
    if (mimic && (master == by_joint.end() || mimic->joint_name == joint))
      warnings_.push_back("joint '" + joint + "': mimics '" + mimic->joint_name + "', which is not another joint of body '" +
                          body.name + "'; modelled as an independent joint");
    master_of.emplace(joint, master == by_joint.end() || mimic->joint_name == joint ? nullptr :
                                                                                      &body.segments[master->second]);
  }
  for (const std::string& name : joint_document_order_)
  {
    const auto found = by_joint.find(name);
    if (found == by_joint.end() || master_of.at(name))
      continue;
    Segment& segment = body.segments[found->second];
    segment.coordinate = static_cast<int>(body.dofs());
    const urdf::JointConstSharedPtr joint = model_->getJoint(name);
    const bool limited = joint->type != urdf::Joint::CONTINUOUS && joint->limits;
    body.joint_names.push_back(name);
    body.joint_lower.push_back(limited ? joint->limits->lower : -std::numeric_limits<double>::infinity());
    body.joint_upper.push_back(limited ? joint->limits->upper : std::numeric_limits<double>::infinity());
  }
  for (Segment& segment : body.segments)
  {
    // Follow the chain of masters (at most one step per segment) to an independent joint.
    double multiplier = 1.0, offset = 0.0;
    const Segment* current = &segment;
    for (std::size_t step = 0; current->coordinate < 0 && !current->joint.empty(); ++step)
    {
      const urdf::JointMimicSharedPtr& mimic = model_->getJoint(current->joint)->mimic;
      const Segment* master = step < body.segments.size() ? master_of.at(current->joint) : nullptr;
      if (!master)
        throw SceneDescriptionError("joint '" + segment.joint + "': its <mimic> chain is circular");
      offset = multiplier * mimic->offset + offset;
      multiplier *= mimic->multiplier;
      current = master;
    }
    if (current != &segment)
    {
      segment.coordinate = current->coordinate;
      segment.multiplier = multiplier;
      segment.offset = offset;
    }
  }
}

// A coordinate whose joints move no mass makes M singular in it.
void SceneBuilder::warnIfCoordinatesMoveNoMass(const ArticulatedBody& body)
{
  std::vector<double> subtree_mass(body.segments.size(), 0.0);
  for (std::size_t s = body.segments.size(); s-- > 0;)
  {
    subtree_mass[s] += body.segments[s].mass_properties.mass;
    if (body.segments[s].parent >= 0)
      subtree_mass[static_cast<std::size_t>(body.segments[s].parent)] += subtree_mass[s];
  }
  std::vector<double> moved(body.dofs(), 0.0);
  for (std::size_t s = 0; s < body.segments.size(); ++s)
    if (body.segments[s].coordinate >= 0)
      moved[static_cast<std::size_t>(body.segments[s].coordinate)] += subtree_mass[s];
  for (std::size_t j = 0; j < body.joint_names.size(); ++j)
    if (!(moved[body.rootCoordinates() + j] > 0.0))
      reportImplausible("joint '" + body.joint_names[j] + "' of body '" + body.name +
                            "': moves no mass, so M(x) is singular in its coordinate (set ~density to give links "
                            "without <inertial> a mass from their geometry)",
                        "loaded as given");
  if (body.floating_root && !(subtree_mass[0] > 0.0))
    reportImplausible("body '" + body.name + "': no mass in any of its links, so M(x) is singular "
                                             "(set ~density to give links without <inertial> a mass from their geometry)",
                      "loaded as given");
}

}  // namespace detail
}  // namespace diff_rigid_body
