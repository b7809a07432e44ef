#include "diff_rigid_body/urdf_scene.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <urdf_world/types.h>
#include <urdf_model/model.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass_properties.h"
#include "diff_rigid_body/mesh_loader.h"
#include "diff_rigid_body/rpy.h"
#include "body_names.h"
#include "identical_positions.h"
#include "link_geometry.h"
#include "urdf_model.h"

namespace diff_rigid_body
{
namespace
{
/// [rad] A floating body whose initial pitch is this close to +-pi/2 loads with a warning.
constexpr double kGimbalLockWarningAngle = 1e-6;

bool isFixed(const urdf::JointConstSharedPtr& joint)
{
  return joint && joint->type == urdf::Joint::FIXED;
}

class SceneBuilder
{
public:
  SceneBuilder(const std::string& urdf_xml, const SceneOptions& options) : options_(options), meshes_(options)
  {
    document_order_ = detail::linkNamesInDocumentOrder(urdf_xml);
    model_ = detail::parseUrdfModel(urdf_xml);
    if (!model_->getRoot())
      throw SceneDescriptionError("robot description: no root link");
    if (options_.density && !(std::isfinite(*options_.density) && *options_.density > 0.0))
    {
      std::ostringstream why;
      why << "parameter density: must be finite and > 0 kg/m^3, got " << *options_.density;
      throw SceneDescriptionError(why.str());
    }
  }

  Scene build()
  {
    Scene scene;
    placeLinks(model_->getRoot(), Eigen::Isometry3d::Identity(), "");
    const std::string root = model_->getRoot()->name;
    scene.fixed_frame = options_.fixed_frame.empty() ? root : options_.fixed_frame;
    const auto fixed = owner_.find(scene.fixed_frame);
    if (fixed == owner_.end() || !fixed->second.empty())
      throw SceneDescriptionError("parameter fixed_frame: '" + scene.fixed_frame + "' is not the root link '" + root +
                                  "' or a link fixed to it");
    const Eigen::Isometry3d fixed_from_root = pose_in_root_.at(scene.fixed_frame).inverse();

    std::vector<std::string> body_links;
    for (const std::string& name : document_order_)
    {
      const std::string& owner = owner_.at(name);
      if (owner.empty())
      {
        if (name != scene.fixed_frame)
          scene.static_links.push_back({ name, fixed_from_root * pose_in_root_.at(name) });
      }
      else if (owner == name)
        body_links.push_back(name);
      else
        merged_links_[owner].push_back(name);  // one pass: loading stays linear in the links
    }
    if (body_links.empty())
      throw SceneDescriptionError("robot description: no body (no link is the child of a floating, revolute, "
                                  "continuous, prismatic or planar joint)");

    std::set<std::string> selected(options_.bodies.begin(), options_.bodies.end());
    for (const std::string& name : options_.bodies)
    {
      if (std::find(body_links.begin(), body_links.end(), name) == body_links.end())
        throw SceneDescriptionError("parameter bodies: unknown body '" + name +
                                    "' (bodies: " + detail::formatBodyNames(body_links) + ")");
    }

    for (const std::string& name : body_links)
    {
      if (!selected.empty() && !selected.count(name))
        continue;
      scene.bodies.push_back(buildBody(name, fixed_from_root));
      const urdf::JointConstSharedPtr& joint = model_->getLink(name)->parent_joint;
      if (joint->type != urdf::Joint::FLOATING)
        scene.unmodelled_joints.push_back("joint '" + joint->name + "' (" + detail::jointTypeName(joint->type) +
                                          "): its constraint is not modelled; child '" + name +
                                          "' is a free body posed at joint value 0");
    }
    scene.warnings = std::move(warnings_);
    return scene;
  }

private:
  // Pose of every link in the root frame at zero joint values, and its owner:
  // "" for a static link, else the body link it belongs to. Depth first with
  // an explicit stack: a chain of 10^5 links must not overflow the call stack.
  void placeLinks(const urdf::LinkConstSharedPtr& root, const Eigen::Isometry3d& root_pose,
                  const std::string& root_owner)
  {
    struct Pending
    {
      urdf::LinkConstSharedPtr link;
      Eigen::Isometry3d pose;
      std::string owner;
    };
    std::vector<Pending> stack{ { root, root_pose, root_owner } };
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
        const Eigen::Isometry3d child_pose = next.pose * detail::toIsometry((*joint)->parent_to_joint_origin_transform);
        if (!child_pose.matrix().allFinite())
          throw SceneDescriptionError("joint '" + (*joint)->name + "': <origin> is not finite");
        stack.push_back({ child, child_pose, isFixed(*joint) ? next.owner : child->name });
      }
    }
  }

  SceneBody buildBody(const std::string& body_name, const Eigen::Isometry3d& fixed_from_root)
  {
    SceneBody scene_body;
    scene_body.body.name = body_name;
    const urdf::JointConstSharedPtr& joint = model_->getLink(body_name)->parent_joint;
    scene_body.joint_name = joint->name;
    scene_body.joint_type = detail::jointTypeName(joint->type);

    const Eigen::Isometry3d body_in_root = pose_in_root_.at(body_name);
    std::vector<std::pair<Eigen::Isometry3d, MassProperties>> link_masses;
    std::vector<std::pair<std::size_t, Eigen::Vector3d>> link_vertices;  // (link slot, position in body link frame)

    std::vector<std::string> members{ body_name };
    for (const std::string& name : merged_links_[body_name])  // document order
      members.push_back(name);

    for (const std::string& name : members)
    {
      LinkInBody slot;
      slot.name = name;
      slot.pose_in_body_link = body_in_root.inverse() * pose_in_root_.at(name);
      slot.mass_properties = addLinkGeometry(*model_->getLink(name), slot.pose_in_body_link, scene_body.links.size(),
                                             link_vertices);
      if (slot.mass_properties.mass > 0.0)
        link_masses.emplace_back(slot.pose_in_body_link, slot.mass_properties);
      scene_body.links.push_back(std::move(slot));
    }

    const MassProperties composite = bodyMassProperties(body_name, link_masses);
    scene_body.body.mass = composite.mass;
    scene_body.body.com_offset = composite.com;
    scene_body.body.inertia_body = composite.inertia;
    joinBodyVertices(link_vertices, composite.com, scene_body);

    // Initial state: link axes' RPY and COM position, in the fixed frame.
    const Eigen::Isometry3d body_in_fixed = fixed_from_root * body_in_root;
    scene_body.initial_state.head<3>() = matrixToRpy(body_in_fixed.linear());
    scene_body.initial_state.tail<3>() = body_in_fixed * composite.com;
    if (!scene_body.initial_state.allFinite())
      throw SceneDescriptionError("body '" + body_name +
                                  "': initial state is not finite (its joint origins and COM offset add up "
                                  "beyond the range of double)");
    warnIfGimbalLocked(scene_body);
    return scene_body;
  }

  // Appends the vertices of one member link's geometry (in the body link
  // frame) to `link_vertices`, and returns the link's mass properties in its
  // own frame: from <inertial>, else from its geometry and ~density, else
  // massless. Implausible inertia is reported (or refused when strict).
  MassProperties addLinkGeometry(const urdf::Link& link, const Eigen::Isometry3d& pose_in_body_link, std::size_t slot,
                                 std::vector<std::pair<std::size_t, Eigen::Vector3d>>& link_vertices)
  {
    std::vector<std::pair<Eigen::Isometry3d, MassProperties>> geometry_masses;
    for (const auto& [origin, geometry] : detail::linkGeometries(link, options_.geometry))
    {
      if (!origin.matrix().allFinite())
        throw SceneDescriptionError("link '" + link.name + "': geometry <origin> is not finite");
      const TriangleMesh mesh = meshes_.mesh(*geometry, link.name);
      const Eigen::Isometry3d in_body_link = pose_in_body_link * origin;
      for (Eigen::Index v = 0; v < mesh.vertices.cols(); ++v)
        link_vertices.emplace_back(slot, in_body_link * mesh.vertices.col(v));
      if (!link.inertial && options_.density)
        geometry_masses.emplace_back(origin, detail::geometryMassProperties(*geometry, mesh, *options_.density, link.name));
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
  MassProperties inertialMassProperties(const std::string& link_name, const urdf::Inertial& inertial)
  {
    const Eigen::Isometry3d frame = detail::toIsometry(inertial.origin);
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

  // Composite of the body's massive links in the body link frame. A body
  // without mass has its COM at the link origin and M = 0 (reported).
  MassProperties bodyMassProperties(const std::string& body_name,
                                    const std::vector<std::pair<Eigen::Isometry3d, MassProperties>>& link_masses)
  {
    if (link_masses.empty())
    {
      reportImplausible("body '" + body_name +
                            "': no mass in its link or merged links, so M(q) = 0 and no coordinate moves mass "
                            "(set ~density to give links without <inertial> a mass from their geometry)",
                        "loaded with M(q) = 0");
      return MassProperties();
    }
    const MassProperties composite = combineMassProperties(link_masses, "body '" + body_name + "'");
    checkMassProperties("body '" + body_name + "'", composite.mass, composite.inertia);  // undefined: throws
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(composite.inertia, Eigen::EigenvaluesOnly);
    if (!(solver.eigenvalues()[0] > 0.0))
      reportImplausible("body '" + body_name + "': a principal moment of its inertia is 0, so M(q) is singular in " +
                            "its rotation coordinates (phi, theta, psi)",
                        "loaded as given");
    return composite;
  }

  // Unique positions in the body frame (origin at the COM), in first
  // occurrence order; each link's new vertices are contiguous.
  void joinBodyVertices(const std::vector<std::pair<std::size_t, Eigen::Vector3d>>& link_vertices,
                        const Eigen::Vector3d& com, SceneBody& scene_body) const
  {
    Matrix3X<double> points(3, static_cast<Eigen::Index>(link_vertices.size()));
    for (std::size_t k = 0; k < link_vertices.size(); ++k)
      points.col(static_cast<Eigen::Index>(k)) = link_vertices[k].second - com;
    const detail::IdenticalPositions positions = detail::joinIdenticalPositions(points);
    for (std::size_t k = 0; k < link_vertices.size(); ++k)
    {
      LinkInBody& link = scene_body.links[link_vertices[k].first];
      const std::uint32_t position = positions.position_of[k];
      if (positions.first_point[position] == static_cast<Eigen::Index>(k))
        ++link.new_vertex_count;
      link.vertex_indices.push_back(position);
    }
    scene_body.body.vertices.resize(3, static_cast<Eigen::Index>(positions.first_point.size()));
    for (std::size_t i = 0; i < positions.first_point.size(); ++i)
      scene_body.body.vertices.col(static_cast<Eigen::Index>(i)) = points.col(positions.first_point[i]);
    if (!scene_body.body.vertices.allFinite())
      throw SceneDescriptionError("body '" + scene_body.body.name +
                                  "': vertex coordinates overflow (check mesh scales)");
  }

  // A body whose initial pitch is within kGimbalLockWarningAngle of +-pi/2
  // starts where M(q) is singular: cos(theta) <= sin(1e-6).
  void warnIfGimbalLocked(const SceneBody& scene_body)
  {
    const double theta = scene_body.initial_state[1];
    if (std::abs(std::cos(theta)) > std::sin(kGimbalLockWarningAngle))
      return;
    std::ostringstream why;
    why.precision(17);
    why << "body '" << scene_body.body.name << "' (joint '" << scene_body.joint_name << "', "
        << scene_body.joint_type << ") starts at gimbal lock: pitch theta = " << theta << " rad, cos(theta) = "
        << std::cos(theta) << "; M(q) is singular there (rank 5)";
    warnings_.push_back(why.str());
  }

  // An implausible finding: a warning saying what was done about it
  // (`consequence`), or a refusal with ~strict_inertia.
  void reportImplausible(const std::string& finding, const std::string& consequence)
  {
    if (options_.strict_inertia)
      throw InvalidInertiaError(finding + " (refused: ~strict_inertia is true)");
    warnings_.push_back(finding + "; " + consequence + " (~strict_inertia: true refuses it)");
  }

  const SceneOptions& options_;
  urdf::ModelInterfaceSharedPtr model_;
  std::vector<std::string> document_order_;
  std::unordered_map<std::string, Eigen::Isometry3d> pose_in_root_;
  std::unordered_map<std::string, std::string> owner_;
  std::unordered_map<std::string, std::vector<std::string>> merged_links_;  ///< body -> merged links, document order
  detail::GeometryMeshes meshes_;
  std::vector<std::string> warnings_;
};

}  // namespace

Scene loadSceneFromUrdf(const std::string& urdf_xml, const SceneOptions& options)
{
  return SceneBuilder(urdf_xml, options).build();
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
