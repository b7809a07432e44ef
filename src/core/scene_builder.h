// Builds a Scene from urdfdom's model (urdf_scene.h has the semantics).
// Internal to the core:
//   scene_builder.cpp      link placement, link geometry and mass properties,
//                          rigid groups of links (a free body or a segment);
//   urdf_scene.cpp         the scene: static links, bodies, selection;
//   articulated_scene.cpp  kinematic trees for JointHandling::Model.
#pragma once

#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <urdf_model/model.h>
#include <urdf_world/types.h>

#include "diff_rigid_body/urdf_scene.h"
#include "link_geometry.h"

namespace diff_rigid_body
{
namespace detail
{
/// Revolute, continuous and prismatic joints: one coordinate each.
inline bool movesOneCoordinate(int joint_type)
{
  return joint_type == urdf::Joint::REVOLUTE || joint_type == urdf::Joint::CONTINUOUS ||
         joint_type == urdf::Joint::PRISMATIC;
}

class SceneBuilder
{
public:
  SceneBuilder(const std::string& urdf_xml, const SceneOptions& options);
  Scene build();

private:
  /// A rigid group of links: a moving link and the links fixed to it.
  struct RigidGroup
  {
    std::vector<LinkInBody> links;  ///< the moving link first, then merged links in document order
    MassProperties mass;            ///< composite, in the moving link's frame
    Matrix3X<double> vertices;      ///< unique positions: body frame (free body) or link frame (segment)
  };

  // scene_builder.cpp
  void placeLinks(const urdf::LinkConstSharedPtr& root);
  /// A free body's group has its vertices about the COM and is warned about
  /// as a body (no mass, a zero principal moment); a segment's vertices are
  /// in its link frame.
  RigidGroup buildRigidGroup(const std::string& link_name, bool free_body);
  MassProperties addLinkGeometry(const urdf::Link& link, const Eigen::Isometry3d& pose_in_body_link, std::size_t slot,
                                 std::vector<std::pair<std::size_t, Eigen::Vector3d>>& link_vertices);
  MassProperties inertialMassProperties(const std::string& link_name, const urdf::Inertial& inertial);
  MassProperties groupMassProperties(const std::string& group_name,
                                     const std::vector<std::pair<Eigen::Isometry3d, MassProperties>>& link_masses,
                                     bool free_body);
  void joinVertices(const std::vector<std::pair<std::size_t, Eigen::Vector3d>>& link_vertices,
                    const Eigen::Vector3d& origin, const std::string& group_name, RigidGroup& group) const;
  void warnIfGimbalLocked(const std::string& body_name, const std::string& joint_name, const std::string& joint_type,
                          double theta);
  void reportImplausible(const std::string& finding, const std::string& consequence);

  // urdf_scene.cpp
  SceneBody buildFreeBody(const std::string& body_name, const Eigen::Isometry3d& fixed_from_root);
  std::vector<std::string> bodyRoots(const std::vector<std::string>& moving_links) const;
  bool isBodyRoot(const std::string& link_name) const;

  // articulated_scene.cpp
  SceneBody buildArticulatedBody(const std::string& root_name, const Eigen::Isometry3d& fixed_from_root);
  std::vector<std::string> treeSegments(const std::string& root_name) const;
  Segment segmentJoint(const urdf::Joint& joint, const std::unordered_map<std::string, std::size_t>& segment_index,
                       const Eigen::Isometry3d& fixed_from_root) const;
  void assignCoordinates(ArticulatedBody& body);
  void warnIfCoordinatesMoveNoMass(const ArticulatedBody& body);

  const SceneOptions& options_;
  urdf::ModelInterfaceSharedPtr model_;
  std::vector<std::string> document_order_;        ///< link names
  std::vector<std::string> joint_document_order_;  ///< joint names
  std::unordered_map<std::string, std::size_t> link_document_index_;
  std::unordered_map<std::string, Eigen::Isometry3d> pose_in_root_;  ///< every link at zero joint values
  /// "" for a static link, else the moving link whose rigid group it is in.
  std::unordered_map<std::string, std::string> owner_;
  std::unordered_map<std::string, std::vector<std::string>> merged_links_;  ///< moving link -> merged links, document order
  GeometryMeshes meshes_;
  std::vector<std::string> warnings_;
};

}  // namespace detail
}  // namespace diff_rigid_body
