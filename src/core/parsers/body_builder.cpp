#include "parsers/body_builder.h"

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <sstream>
#include <unordered_map>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/multibody/rpy.h"
#include "parsers/body_coordinates.h"

namespace diff_rigid_body
{
namespace detail
{
namespace
{
// The segments of the tree under `root` in document order of their links,
// except that a parent always comes before its children: the next segment
// is the earliest in the document among those whose parent is placed.
std::vector<std::string> treeSegments(const UrdfDescription& description, const std::string& root)
{
  using Ready = std::pair<std::size_t, std::string>;  // (document index, link)
  std::priority_queue<Ready, std::vector<Ready>, std::greater<Ready>> ready;
  ready.emplace(description.link_index.at(root), root);
  std::vector<std::string> order;
  while (!ready.empty())
  {
    const std::string segment = ready.top().second;
    ready.pop();
    order.push_back(segment);
    // Child segments: 1-dof joints below the segment's link or its merged links.
    std::vector<const urdf::Link*> rigid{ &description.link(segment) };
    for (std::size_t k = 0; k < rigid.size(); ++k)
      for (const urdf::JointSharedPtr& joint : rigid[k]->child_joints)
      {
        if (joint->type == urdf::Joint::FIXED)
          rigid.push_back(&description.link(joint->child_link_name));
        else if (movesOneCoordinate(joint->type))
          ready.emplace(description.link_index.at(joint->child_link_name), joint->child_link_name);
      }
  }
  return order;
}

// A joint segment's joint: type, unit axis, and placement in its parent
// segment's frame (in the fixed frame below a static link).
void setJoint(const UrdfDescription& description, const LinkTree& tree, const BodyModel& body,
              const std::unordered_map<std::string, std::size_t>& segment_index,
              const Eigen::Isometry3d& fixed_from_root, Segment& segment)
{
  const urdf::Joint& joint = *description.link(segment.link).parent_joint;
  segment.joint_type = joint.type == urdf::Joint::PRISMATIC ? JointType::Prismatic : JointType::Revolute;
  const Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
  if (!axis.allFinite() || !(axis.norm() > 0.0))
    throw SceneDescriptionError("joint '" + joint.name + "': <axis> must be a finite, non-zero vector");
  segment.axis = axis.normalized();
  segment.axis_index = -1;
  for (int k = 0; k < 3; ++k)
    if (std::abs(segment.axis[k]) == 1.0 && segment.axis[(k + 1) % 3] == 0.0 && segment.axis[(k + 2) % 3] == 0.0)
      segment.axis_index = k;
  const Eigen::Isometry3d origin = toIsometry(joint.parent_to_joint_origin_transform);
  const std::string& parent_segment = tree.ownerOf(description, joint.parent_link_name);
  Eigen::Isometry3d placement;
  if (parent_segment.empty())
    placement = fixed_from_root * tree.pose(description, joint.parent_link_name) * origin;
  else
  {
    segment.parent = static_cast<int>(segment_index.at(parent_segment));
    const Segment& parent = body.segments[static_cast<std::size_t>(segment.parent)];
    placement = joint.parent_link_name == parent_segment ? origin :
                                                           tree.pose(description, parent_segment).inverse() *
                                                               tree.pose(description, joint.parent_link_name) * origin;
    placement.translation() += parent.link_origin;  // the parent's link frame to its segment frame
  }
  segment.placement_rotation = placement.linear();
  segment.placement_translation = placement.translation();
  segment.placement_rotates = !(segment.placement_rotation.array() == Eigen::Matrix3d::Identity().array()).all();
}

// Appends segment k's rigid group: its mass properties, vertex range and links.
void addRigidGroup(RigidGroup group, std::size_t k, Segment& segment, BodyModel& body,
                   std::vector<Matrix3X<double>>& vertex_blocks, std::size_t& vertex_count)
{
  segment.inertia = group.mass;
  if (segment.joint_type == JointType::Free)
  {
    // The segment frame sits at the COM: the link origin at -COM.
    segment.link_origin = -group.mass.com;
    segment.inertia.com.setZero();
  }
  segment.vertex_begin = static_cast<std::uint32_t>(vertex_count);
  segment.vertex_count = static_cast<std::uint32_t>(group.vertices.cols());
  segment.vertex_radius = group.vertices.cols() ? group.vertices.colwise().norm().maxCoeff() : 0.0;
  for (LinkInBody& link : group.links)
  {
    link.segment = k;
    for (std::uint32_t& v : link.vertex_indices)
      v += segment.vertex_begin;
    body.links.push_back(std::move(link));
  }
  vertex_count += static_cast<std::size_t>(group.vertices.cols());
  if (vertex_count > std::numeric_limits<std::uint32_t>::max())
    throw SceneDescriptionError("body '" + body.name + "': more than 2^32 - 1 vertices");
  vertex_blocks.push_back(std::move(group.vertices));
}

// A free root whose initial pitch is within 1e-6 rad of +-pi/2 starts where
// M is singular: cos(theta) <= sin(1e-6).
void warnIfGimbalLocked(const BodyModel& body, double theta, LoadContext& context)
{
  constexpr double kGimbalLockWarningAngle = 1e-6;  // [rad]
  if (std::abs(std::cos(theta)) > std::sin(kGimbalLockWarningAngle))
    return;
  std::ostringstream why;
  why.precision(17);
  why << "body '" << body.name << "' (joint '" << body.joint_name << "', " << body.joint_type
      << ") starts at gimbal lock: pitch theta = " << theta << " rad, cos(theta) = " << std::cos(theta)
      << "; M(q) is singular there (rank 5)";
  context.warnings.push_back(why.str());
}

// x at load: a free root's link axes (RPY) and COM in the fixed frame, every joint at 0.
void setInitialState(const UrdfDescription& description, const LinkTree& tree, const Eigen::Isometry3d& fixed_from_root,
                     BodyModel& body, LoadContext& context)
{
  body.initial_x = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(body.coordinates));
  if (!body.hasFreeRoot())
    return;
  const Eigen::Isometry3d root_in_fixed = fixed_from_root * tree.pose(description, body.name);
  body.initial_x.head<3>() = matrixToRpy(root_in_fixed.linear());
  body.initial_x.segment<3>(3) = root_in_fixed * (-body.segments[0].link_origin);
  if (!body.initial_x.allFinite())
    throw SceneDescriptionError("body '" + body.name +
                                "': initial state is not finite (its joint origins and COM offset add up "
                                "beyond the range of double)");
  warnIfGimbalLocked(body, body.initial_x[THETA], context);
}
}  // namespace

BodyModel buildBodyModel(const UrdfDescription& description, const LinkTree& tree, const std::string& root_link,
                         RootKind root_kind, bool joints_below, const Eigen::Isometry3d& fixed_from_root,
                         LoadContext& context)
{
  BodyModel body;
  body.name = root_link;
  const urdf::Joint& root_joint = *description.link(root_link).parent_joint;
  body.joint_name = root_joint.name;
  body.joint_type = jointTypeName(root_joint.type);
  const std::vector<std::string> segment_links =
      joints_below ? treeSegments(description, root_link) : std::vector<std::string>{ root_link };
  const bool free_object = root_kind == RootKind::Free && segment_links.size() == 1;
  std::unordered_map<std::string, std::size_t> segment_index;
  for (std::size_t k = 0; k < segment_links.size(); ++k)
    segment_index.emplace(segment_links[k], k);
  std::vector<Matrix3X<double>> vertex_blocks;
  std::size_t vertex_count = 0;
  for (std::size_t k = 0; k < segment_links.size(); ++k)
  {
    Segment segment;
    segment.link = segment_links[k];
    segment.joint = description.link(segment.link).parent_joint->name;
    if (k == 0 && root_kind == RootKind::Free)
      segment.joint_type = JointType::Free;
    else
      setJoint(description, tree, body, segment_index, fixed_from_root, segment);
    const GroupRole role = segment.joint_type != JointType::Free ? GroupRole::JointSegment :
                           free_object                           ? GroupRole::FreeObject :
                                                                   GroupRole::FreeRoot;
    addRigidGroup(mergeRigidGroup(description, tree, segment.link, role, context), k, segment, body, vertex_blocks,
                  vertex_count);
    body.segments.push_back(std::move(segment));
  }
  body.vertices.resize(3, static_cast<Eigen::Index>(vertex_count));
  for (std::size_t k = 0; k < body.segments.size(); ++k)
    body.vertices.middleCols(body.segments[k].vertex_begin, body.segments[k].vertex_count) = vertex_blocks[k];
  body.vertex_columns = body.vertices.transpose();
  buildDofs(assignCoordinates(description, body, context), body);
  if (!free_object)
    warnIfCoordinatesMoveNoMass(body, context);
  body.kernels = free_object ? BodyKernels::FreeSegment : BodyKernels::Tree;
  setInitialState(description, tree, fixed_from_root, body, context);
  return body;
}

}  // namespace detail
}  // namespace diff_rigid_body
