#include "scene_builder.h"

#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <urdf_world/types.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass_properties.h"
#include "diff_rigid_body/mesh_loader.h"
#include "identical_positions.h"
#include "urdf_model.h"
#include "urdf_topology.h"

namespace diff_rigid_body
{
namespace detail
{
SceneBuilder::SceneBuilder(const std::string& urdf_xml, const SceneOptions& options)
  : options_(options), meshes_(options)
{
  document_order_ = namesInDocumentOrder(urdf_xml, "link");
  joint_document_order_ = namesInDocumentOrder(urdf_xml, "joint");
  model_ = parseUrdfModel(urdf_xml);
  std::vector<JointEdge> edges;
  for (const std::string& name : joint_document_order_)
    if (const urdf::JointConstSharedPtr joint = model_->getJoint(name))
      edges.push_back({ name, joint->parent_link_name, joint->child_link_name });
  checkTreeTopology(document_order_, edges);
  if (!model_->getRoot())
    throw SceneDescriptionError("robot description: no root link");
  if (options_.density && !(std::isfinite(*options_.density) && *options_.density > 0.0))
  {
    std::ostringstream why;
    why << "parameter density: must be finite and > 0 kg/m^3, got " << *options_.density;
    throw SceneDescriptionError(why.str());
  }
}

// Pose of every link in the root frame at zero joint values, and its owner:
// "" for a static link, else the moving link whose rigid group it is in.
// Depth first with an explicit stack: a chain of 10^5 links must not
// overflow the call stack.
void SceneBuilder::placeLinks(const urdf::LinkConstSharedPtr& root)
{
  struct Pending
  {
    urdf::LinkConstSharedPtr link;
    Eigen::Isometry3d pose;
    std::string owner;
  };
  std::vector<Pending> stack{ { root, Eigen::Isometry3d::Identity(), "" } };
  while (!stack.empty())
  {
    const Pending next = std::move(stack.back());
    stack.pop_back();
    pose_in_root_[next.link->name] = next.pose;
    owner_[next.link->name] = next.owner;
    // Children pushed in reverse, so that they are visited in order.
    for (auto joint = next.link->child_joints.rbegin(); joint != next.link->child_joints.rend(); ++joint)
    {
      const urdf::LinkConstSharedPtr child = model_->getLink((*joint)->child_link_name);
      const Eigen::Isometry3d child_pose = next.pose * toIsometry((*joint)->parent_to_joint_origin_transform);
      if (!child_pose.matrix().allFinite())
        throw SceneDescriptionError("joint '" + (*joint)->name + "': <origin> is not finite");
      const bool fixed = (*joint)->type == urdf::Joint::FIXED;
      stack.push_back({ child, child_pose, fixed ? next.owner : child->name });
    }
  }
}

SceneBuilder::RigidGroup SceneBuilder::buildRigidGroup(const std::string& link_name, bool free_body)
{
  RigidGroup group;
  const Eigen::Isometry3d group_in_root = pose_in_root_.at(link_name);
  std::vector<std::pair<Eigen::Isometry3d, MassProperties>> link_masses;
  std::vector<std::pair<std::size_t, Eigen::Vector3d>> link_vertices;  // (link slot, position in the group's link frame)

  std::vector<std::string> members{ link_name };
  for (const std::string& name : merged_links_[link_name])  // document order
    members.push_back(name);
  for (const std::string& name : members)
  {
    LinkInBody slot;
    slot.name = name;
    slot.pose_in_body_link = group_in_root.inverse() * pose_in_root_.at(name);
    slot.mass_properties =
        addLinkGeometry(*model_->getLink(name), slot.pose_in_body_link, group.links.size(), link_vertices);
    if (slot.mass_properties.mass > 0.0)
      link_masses.emplace_back(slot.pose_in_body_link, slot.mass_properties);
    group.links.push_back(std::move(slot));
  }
  group.mass = groupMassProperties(link_name, link_masses, free_body);
  joinVertices(link_vertices, free_body ? group.mass.com : Eigen::Vector3d::Zero(), link_name, group);
  return group;
}

// Appends the vertices of one member link's geometry (in the group's link
// frame) to `link_vertices`, and returns the link's mass properties in its
// own frame: from <inertial>, else from its geometry and ~density, else
// massless. Implausible inertia is reported (or refused when strict).
MassProperties SceneBuilder::addLinkGeometry(const urdf::Link& link, const Eigen::Isometry3d& pose_in_body_link,
                                             std::size_t slot,
                                             std::vector<std::pair<std::size_t, Eigen::Vector3d>>& link_vertices)
{
  std::vector<std::pair<Eigen::Isometry3d, MassProperties>> geometry_masses;
  for (const auto& [origin, geometry] : linkGeometries(link, options_.geometry))
  {
    if (!origin.matrix().allFinite())
      throw SceneDescriptionError("link '" + link.name + "': geometry <origin> is not finite");
    const TriangleMesh mesh = meshes_.mesh(*geometry, link.name);
    const Eigen::Isometry3d in_body_link = pose_in_body_link * origin;
    for (Eigen::Index v = 0; v < mesh.vertices.cols(); ++v)
      link_vertices.emplace_back(slot, in_body_link * mesh.vertices.col(v));
    if (!link.inertial && options_.density)
      geometry_masses.emplace_back(origin, geometryMassProperties(*geometry, mesh, *options_.density, link.name));
  }
  if (link.inertial)
    return inertialMassProperties(link.name, *link.inertial);
  if (!geometry_masses.empty())
    return combineMassProperties(geometry_masses, "link '" + link.name + "' geometry");
  reportImplausible("link '" + link.name + "': no <inertial>" +
                        (options_.density ? std::string(" and no geometry to compute one from") :
                                            std::string(" (set ~density to compute one from its geometry)")),
                    "merged as massless");
  return MassProperties();
}

// <inertial> in the link frame: I_link = R_o I R_o^T about the COM.
MassProperties SceneBuilder::inertialMassProperties(const std::string& link_name, const urdf::Inertial& inertial)
{
  const Eigen::Isometry3d frame = toIsometry(inertial.origin);
  if (!frame.matrix().allFinite())
    throw InvalidInertiaError("link '" + link_name + "' <inertial>: <origin> is not finite");
  Eigen::Matrix3d inertia;
  inertia << inertial.ixx, inertial.ixy, inertial.ixz,  //
      inertial.ixy, inertial.iyy, inertial.iyz,         //
      inertial.ixz, inertial.iyz, inertial.izz;
  const std::string where = "link '" + link_name + "' <inertial>";
  for (const std::string& finding : checkMassProperties(where, inertial.mass, inertia))
    reportImplausible(finding, inertial.mass == 0.0 ? "merged as massless" : "loaded as given");
  if (inertial.mass == 0.0)
    return MassProperties();
  MassProperties properties;
  properties.mass = inertial.mass;
  properties.com = frame.translation();
  properties.inertia = frame.linear() * inertia * frame.linear().transpose();
  return properties;
}

// Composite of the group's massive links in its link frame. A group without
// mass has its COM at the link origin; a free body without mass has M = 0
// (reported).
MassProperties SceneBuilder::groupMassProperties(
    const std::string& group_name, const std::vector<std::pair<Eigen::Isometry3d, MassProperties>>& link_masses,
    bool free_body)
{
  if (link_masses.empty())
  {
    if (free_body)
      reportImplausible("body '" + group_name +
                            "': no mass in its link or merged links, so M(q) = 0 and no coordinate moves mass "
                            "(set ~density to give links without <inertial> a mass from their geometry)",
                        "loaded with M(q) = 0");
    return MassProperties();
  }
  const MassProperties composite = combineMassProperties(link_masses, "body '" + group_name + "'");
  checkMassProperties("body '" + group_name + "'", composite.mass, composite.inertia);  // undefined: throws
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(composite.inertia, Eigen::EigenvaluesOnly);
  if (free_body && !(solver.eigenvalues()[0] > 0.0))
    reportImplausible("body '" + group_name + "': a principal moment of its inertia is 0, so M(q) is singular in " +
                          "its rotation coordinates (phi, theta, psi)",
                      "loaded as given");
  return composite;
}

// Unique positions minus `origin`, in first occurrence order; each link's new
// vertices are contiguous.
void SceneBuilder::joinVertices(const std::vector<std::pair<std::size_t, Eigen::Vector3d>>& link_vertices,
                                const Eigen::Vector3d& origin, const std::string& group_name, RigidGroup& group) const
{
  Matrix3X<double> points(3, static_cast<Eigen::Index>(link_vertices.size()));
  for (std::size_t k = 0; k < link_vertices.size(); ++k)
    points.col(static_cast<Eigen::Index>(k)) = link_vertices[k].second - origin;
  const IdenticalPositions positions = joinIdenticalPositions(points);
  for (std::size_t k = 0; k < link_vertices.size(); ++k)
  {
    LinkInBody& link = group.links[link_vertices[k].first];
    const std::uint32_t position = positions.position_of[k];
    if (positions.first_point[position] == static_cast<Eigen::Index>(k))
      ++link.new_vertex_count;
    link.vertex_indices.push_back(position);
  }
  group.vertices.resize(3, static_cast<Eigen::Index>(positions.first_point.size()));
  for (std::size_t i = 0; i < positions.first_point.size(); ++i)
    group.vertices.col(static_cast<Eigen::Index>(i)) = points.col(positions.first_point[i]);
  if (!group.vertices.allFinite())
    throw SceneDescriptionError("body '" + group_name + "': vertex coordinates overflow (check mesh scales)");
}

// A floating root whose initial pitch is within kGimbalLockWarningAngle of
// +-pi/2 starts where M(q) is singular: cos(theta) <= sin(1e-6).
void SceneBuilder::warnIfGimbalLocked(const std::string& body_name, const std::string& joint_name,
                                      const std::string& joint_type, double theta)
{
  constexpr double kGimbalLockWarningAngle = 1e-6;  // [rad]
  if (std::abs(std::cos(theta)) > std::sin(kGimbalLockWarningAngle))
    return;
  std::ostringstream why;
  why.precision(17);
  why << "body '" << body_name << "' (joint '" << joint_name << "', " << joint_type
      << ") starts at gimbal lock: pitch theta = " << theta << " rad, cos(theta) = " << std::cos(theta)
      << "; M(q) is singular there (rank 5)";
  warnings_.push_back(why.str());
}

// An implausible finding: a warning saying what was done about it
// (`consequence`), or a refusal with ~strict_inertia.
void SceneBuilder::reportImplausible(const std::string& finding, const std::string& consequence)
{
  if (options_.strict_inertia)
    throw InvalidInertiaError(finding + " (refused: ~strict_inertia is true)");
  warnings_.push_back(finding + "; " + consequence + " (~strict_inertia: true refuses it)");
}

}  // namespace detail
}  // namespace diff_rigid_body
