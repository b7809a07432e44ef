#include "parsers/rigid_group.h"

#include <cmath>
#include <sstream>
#include <utility>

#include <Eigen/Eigenvalues>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mass_properties.h"
#include "mass/identical_positions.h"

namespace diff_rigid_body
{
namespace detail
{
void LoadContext::implausible(const std::string& finding, const std::string& consequence)
{
  if (options.strict_inertia)
    throw InvalidInertiaError(finding + " (refused: ~strict_inertia is true)");
  warnings.push_back(finding + "; " + consequence + " (~strict_inertia: true refuses it)");
}

namespace
{
using LinkVertices = std::vector<std::pair<std::size_t, Eigen::Vector3d>>;  // (link slot, position in the group's link frame)
using PlacedMasses = std::vector<std::pair<Eigen::Isometry3d, MassProperties>>;

// <inertial> in the link frame: I_link = R_o I R_o^T about the COM.
MassProperties inertialMassProperties(const std::string& link_name, const urdf::Inertial& inertial,
                                      LoadContext& context)
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
    context.implausible(finding, inertial.mass == 0.0 ? "merged as massless" : "loaded as given");
  if (inertial.mass == 0.0)
    return MassProperties();
  MassProperties properties;
  properties.mass = inertial.mass;
  properties.com = frame.translation();
  properties.inertia = frame.linear() * inertia * frame.linear().transpose();
  return properties;
}

// Appends the vertices of one member link's geometry (in the group's link
// frame) to `link_vertices` and returns the link's mass properties in its
// own frame: from <inertial>, else from its geometry and ~density, else
// massless (reported).
MassProperties addLinkGeometry(const urdf::Link& link, const Eigen::Isometry3d& pose_in_group, std::size_t slot,
                               LinkVertices& link_vertices, LoadContext& context)
{
  const SceneOptions& options = context.options;
  PlacedMasses geometry_masses;
  for (const auto& [origin, geometry] : linkGeometries(link, options.geometry))
  {
    if (!origin.matrix().allFinite())
      throw SceneDescriptionError("link '" + link.name + "': geometry <origin> is not finite");
    const TriangleMesh mesh = context.meshes.mesh(*geometry, link.name);
    const Eigen::Isometry3d in_group = pose_in_group * origin;
    for (Eigen::Index v = 0; v < mesh.vertices.cols(); ++v)
      link_vertices.emplace_back(slot, in_group * mesh.vertices.col(v));
    if (!link.inertial && options.density)
      geometry_masses.emplace_back(origin, geometryMassProperties(*geometry, mesh, *options.density, link.name));
  }
  if (link.inertial)
    return inertialMassProperties(link.name, *link.inertial, context);
  if (!geometry_masses.empty())
    return combineMassProperties(geometry_masses, "link '" + link.name + "' geometry");
  context.implausible("link '" + link.name + "': no <inertial>" +
                          (options.density ? std::string(" and no geometry to compute one from") :
                                             std::string(" (set ~density to compute one from its geometry)")),
                      "merged as massless");
  return MassProperties();
}

// Composite of the group's massive links in its link frame. A group without
// mass has its COM at the link origin; a free object without mass has
// M = 0 (reported), and one with a zero principal moment a singular M.
MassProperties groupMassProperties(const std::string& group_name, const PlacedMasses& link_masses, GroupRole role,
                                   LoadContext& context)
{
  const bool free_object = role == GroupRole::FreeObject;
  if (link_masses.empty())
  {
    if (free_object)
      context.implausible("body '" + group_name +
                              "': no mass in its link or merged links, so M(q) = 0 and no coordinate moves mass "
                              "(set ~density to give links without <inertial> a mass from their geometry)",
                          "loaded with M(q) = 0");
    return MassProperties();
  }
  const MassProperties composite = combineMassProperties(link_masses, "body '" + group_name + "'");
  checkMassProperties("body '" + group_name + "'", composite.mass, composite.inertia);  // undefined: throws
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(composite.inertia, Eigen::EigenvaluesOnly);
  if (free_object && !(solver.eigenvalues()[0] > 0.0))
    context.implausible("body '" + group_name + "': a principal moment of its inertia is 0, so M(q) is singular in " +
                            "its rotation coordinates (phi, theta, psi)",
                        "loaded as given");
  return composite;
}

// Unique positions minus `origin`, in first occurrence order; each link's new
// vertices are contiguous.
void joinVertices(const LinkVertices& link_vertices, const Eigen::Vector3d& origin, const std::string& group_name,
                  RigidGroup& group)
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
}  // namespace

RigidGroup mergeRigidGroup(const UrdfDescription& description, const LinkTree& tree, const std::string& link,
                           GroupRole role, LoadContext& context)
{
  RigidGroup group;
  const Eigen::Isometry3d group_in_root = tree.pose(description, link);
  PlacedMasses link_masses;
  LinkVertices link_vertices;
  std::vector<std::string> members{ link };
  const auto merged = tree.merged_links.find(link);
  if (merged != tree.merged_links.end())
    members.insert(members.end(), merged->second.begin(), merged->second.end());  // document order
  for (const std::string& name : members)
  {
    LinkInBody slot;
    slot.name = name;
    slot.pose_in_segment_link = group_in_root.inverse() * tree.pose(description, name);
    slot.mass_properties =
        addLinkGeometry(description.link(name), slot.pose_in_segment_link, group.links.size(), link_vertices, context);
    if (slot.mass_properties.mass > 0.0)
      link_masses.emplace_back(slot.pose_in_segment_link, slot.mass_properties);
    group.links.push_back(std::move(slot));
  }
  group.mass = groupMassProperties(link, link_masses, role, context);
  const bool about_com = role != GroupRole::JointSegment;
  joinVertices(link_vertices, about_com ? group.mass.com : Eigen::Vector3d::Zero(), link, group);
  return group;
}

}  // namespace detail
}  // namespace diff_rigid_body
