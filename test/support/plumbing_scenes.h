// A scene with articulated bodies built by hand (no URDF loader), for the
// plumbing tests of SceneQueries and the state file: layouts, offsets and
// dispatch, not the articulated numbers themselves.
//
// Bodies, in scene order:
//   0 "cube", 1 "ball": the free bodies of urdf::twoBodies() (6 dofs each);
//   2 "arm": floating root + joints shoulder (revolute), elbow (revolute),
//     slide (prismatic) and finger_joint (mimic of elbow): 9 dofs, 14 vertices;
//   3 "crane": fixed-base, joints mast_yaw (revolute) and boom_out
//     (prismatic): 2 dofs, 5 vertices.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "diff_rigid_body/articulated_body.h"
#include "diff_rigid_body/urdf_scene.h"
#include "urdf_builders.h"

namespace drb_test
{
namespace plumbing
{
struct SegmentSpec
{
  const char* link;
  int parent;
  const char* joint;
  diff_rigid_body::JointMotion motion;
  Eigen::Vector3d xyz, rpy, axis;
  int coordinate;
  double multiplier, offset, mass;
  std::uint32_t vertices;
};

inline std::shared_ptr<diff_rigid_body::ArticulatedBody> articulated(const std::string& name, bool floating,
                                                                     const std::vector<SegmentSpec>& specs,
                                                                     const std::vector<std::string>& joints)
{
  auto body = std::make_shared<diff_rigid_body::ArticulatedBody>();
  body->name = name;
  body->floating_root = floating;
  std::uint32_t vertex = 0;
  for (const SegmentSpec& spec : specs)
  {
    diff_rigid_body::Segment segment;
    segment.link = spec.link;
    segment.parent = spec.parent;
    segment.joint = spec.joint;
    segment.motion = spec.motion;
    segment.origin = Eigen::Translation3d(spec.xyz) * Eigen::AngleAxisd(spec.rpy[2], Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(spec.rpy[1], Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(spec.rpy[0], Eigen::Vector3d::UnitX());
    segment.axis = spec.axis.normalized();
    segment.coordinate = spec.coordinate;
    segment.multiplier = spec.multiplier;
    segment.offset = spec.offset;
    segment.mass_properties.mass = spec.mass;
    segment.mass_properties.com = Eigen::Vector3d(0.05, -0.01, 0.02) * spec.mass;
    segment.mass_properties.inertia = Eigen::Vector3d(0.02, 0.03, 0.04).asDiagonal();
    segment.mass_properties.inertia *= spec.mass;
    segment.vertex_begin = vertex;
    segment.vertex_count = spec.vertices;
    vertex += spec.vertices;
    body->segments.push_back(segment);
  }
  body->vertices.resize(3, vertex);
  for (Eigen::Index i = 0; i < body->vertices.size(); ++i)
    body->vertices.data()[i] = 0.1 * std::sin(1.7 * static_cast<double>(i) + 0.4);
  body->joint_names = joints;
  body->joint_lower.assign(joints.size(), -3.0);
  body->joint_upper.assign(joints.size(), 3.0);
  return body;
}

inline diff_rigid_body::SceneBody sceneBody(std::shared_ptr<diff_rigid_body::ArticulatedBody> body,
                                            const std::vector<double>& initial)
{
  diff_rigid_body::SceneBody scene_body;
  scene_body.body.name = body->name;
  for (const diff_rigid_body::Segment& segment : body->segments)
    scene_body.body.mass += segment.mass_properties.mass;
  scene_body.initial_state = Eigen::Map<const Eigen::VectorXd>(initial.data(), static_cast<Eigen::Index>(initial.size()));
  scene_body.articulated = std::move(body);
  return scene_body;
}

/// "arm": 9 dofs (floating root, shoulder, elbow, slide; finger_joint mimics elbow).
inline std::shared_ptr<diff_rigid_body::ArticulatedBody> arm()
{
  using diff_rigid_body::JointMotion;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  return articulated(
      "arm", true,
      {
          { "arm", -1, "", JointMotion::Revolute, zero, zero, Eigen::Vector3d::UnitX(), -1, 1.0, 0.0, 2.0, 4 },
          { "upper", 0, "shoulder", JointMotion::Revolute, { 0.1, 0, 0.05 }, { 0, 0.3, 0 }, { 0, 0, 1 }, 6, 1.0, 0.0,
            1.0, 3 },
          { "fore", 1, "elbow", JointMotion::Revolute, { 0.3, 0, 0 }, zero, { 0, 1, 0.2 }, 7, 1.0, 0.0, 0.5, 3 },
          { "slider", 0, "slide", JointMotion::Prismatic, { 0, 0.1, 0 }, { 0.2, 0, 0 }, { 1, 1, 0 }, 8, 1.0, 0.0, 0.3,
            2 },
          { "finger", 2, "finger_joint", JointMotion::Revolute, { 0.2, 0, 0 }, zero, { 1, 0, 0 }, 7, -0.5, 0.1, 0.1,
            2 },
      },
      { "shoulder", "elbow", "slide" });
}

/// "crane": 2 dofs (fixed base: mast_yaw, boom_out).
inline std::shared_ptr<diff_rigid_body::ArticulatedBody> crane()
{
  using diff_rigid_body::JointMotion;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  return articulated("crane", false,
                     {
                         { "mast", -1, "mast_yaw", JointMotion::Revolute, { 1, 0, 0 }, zero, { 0, 0, 1 }, 0, 1.0, 0.0,
                           5.0, 3 },
                         { "boom", 0, "boom_out", JointMotion::Prismatic, { 0, 0, 2 }, zero, { 1, 0, 0 }, 1, 1.0, 0.0,
                           1.0, 2 },
                     },
                     { "mast_yaw", "boom_out" });
}

/// The scene of the header comment; `arm_body` and `crane_body` replace the defaults.
inline diff_rigid_body::Scene scene(std::shared_ptr<diff_rigid_body::ArticulatedBody> arm_body = arm(),
                                    std::shared_ptr<diff_rigid_body::ArticulatedBody> crane_body = crane())
{
  urdf::TwoBodies free_bodies;
  free_bodies.cube_rpy = "0.1 0.2 0.3";
  diff_rigid_body::Scene result = diff_rigid_body::loadSceneFromUrdf(urdf::twoBodies(free_bodies));
  result.bodies.push_back(sceneBody(std::move(arm_body), { 0.1, 0.2, 0.3, 1.0, 2.0, 3.0, 0.4, -0.5, 0.05 }));
  result.bodies.push_back(sceneBody(std::move(crane_body), { 0.7, 0.25 }));
  return result;
}
}  // namespace plumbing
}  // namespace drb_test
