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
#include <string>
#include <vector>

#include "diff_rigid_body/multibody/body_model.h"
#include "diff_rigid_body/parsers/urdf_scene.h"
#include "body_models.h"
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
  diff_rigid_body::JointType motion;  ///< Free for a floating root
  Eigen::Vector3d xyz, rpy, axis;     ///< the joint's <origin> in the parent's link frame, and its <axis>
  int coordinate;
  double multiplier, offset, mass;
  std::uint32_t vertices;
};

/// A body of hand-made segments. Each segment's COM is (0.05, -0.01, 0.02)
/// mass in its link frame, its inertia about the COM mass diag(0.02, 0.03,
/// 0.04), its vertices 0.1 sin(1.7 i + 0.4) in its link frame (i over all
/// the body's vertex coordinates). A floating root's segment frame has its
/// origin at that COM (body_model.h): its vertices, and its children's joint
/// placements, are shifted by link_origin = -COM.
inline diff_rigid_body::BodyModel articulated(const std::string& name, const std::vector<SegmentSpec>& specs,
                                              const std::vector<std::string>& joints,
                                              const std::vector<double>& initial)
{
  namespace drb = diff_rigid_body;
  drb::BodyModel body;
  body.name = name;
  std::uint32_t vertex = 0;
  for (const SegmentSpec& spec : specs)
    vertex += spec.vertices;
  body.vertices.resize(3, vertex);
  for (Eigen::Index i = 0; i < body.vertices.size(); ++i)
    body.vertices.data()[i] = 0.1 * std::sin(1.7 * static_cast<double>(i) + 0.4);
  vertex = 0;
  std::vector<drb_test::core_body::JointCoordinate> coordinates;
  for (const SegmentSpec& spec : specs)
  {
    drb::Segment segment;
    segment.link = spec.link;
    segment.parent = spec.parent;
    segment.joint = spec.joint;
    segment.joint_type = spec.motion;
    const Eigen::Isometry3d origin(Eigen::Translation3d(spec.xyz) *
                                   Eigen::AngleAxisd(spec.rpy[2], Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(spec.rpy[1], Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(spec.rpy[0], Eigen::Vector3d::UnitX()));
    segment.placement_rotation = origin.linear();
    segment.placement_translation = origin.translation();
    if (spec.parent >= 0)  // the parent's link frame to its segment frame
      segment.placement_translation += body.segments[static_cast<std::size_t>(spec.parent)].link_origin;
    segment.axis = spec.axis.normalized();
    drb::MassProperties in_link;
    in_link.mass = spec.mass;
    in_link.com = Eigen::Vector3d(0.05, -0.01, 0.02) * spec.mass;
    in_link.inertia = Eigen::Vector3d(0.02, 0.03, 0.04).asDiagonal();
    in_link.inertia *= spec.mass;
    segment.inertia = in_link;
    if (spec.motion == drb::JointType::Free)
    {
      segment.link_origin = -in_link.com;
      segment.inertia.com.setZero();
    }
    segment.vertex_begin = vertex;
    segment.vertex_count = spec.vertices;
    body.vertices.middleCols(vertex, spec.vertices).colwise() += segment.link_origin;
    vertex += spec.vertices;
    drb_test::core_body::addSegmentLink(body, segment, in_link);
    coordinates.push_back({ spec.coordinate, spec.multiplier, spec.offset });
    body.segments.push_back(segment);
  }
  body.joint_names = joints;
  body.joint_lower.assign(joints.size(), -3.0);
  body.joint_upper.assign(joints.size(), 3.0);
  body.initial_x = Eigen::Map<const Eigen::VectorXd>(initial.data(), static_cast<Eigen::Index>(initial.size()));
  drb_test::core_body::deriveFields(body, coordinates);
  return body;
}

/// "arm": 9 dofs (floating root, shoulder, elbow, slide; finger_joint mimics elbow).
inline diff_rigid_body::BodyModel arm()
{
  using diff_rigid_body::JointType;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  return articulated(
      "arm",
      {
          { "arm", -1, "", JointType::Free, zero, zero, Eigen::Vector3d::UnitX(), -1, 1.0, 0.0, 2.0, 4 },
          { "upper", 0, "shoulder", JointType::Revolute, { 0.1, 0, 0.05 }, { 0, 0.3, 0 }, { 0, 0, 1 }, 6, 1.0, 0.0,
            1.0, 3 },
          { "fore", 1, "elbow", JointType::Revolute, { 0.3, 0, 0 }, zero, { 0, 1, 0.2 }, 7, 1.0, 0.0, 0.5, 3 },
          { "slider", 0, "slide", JointType::Prismatic, { 0, 0.1, 0 }, { 0.2, 0, 0 }, { 1, 1, 0 }, 8, 1.0, 0.0, 0.3,
            2 },
          { "finger", 2, "finger_joint", JointType::Revolute, { 0.2, 0, 0 }, zero, { 1, 0, 0 }, 7, -0.5, 0.1, 0.1,
            2 },
      },
      { "shoulder", "elbow", "slide" }, { 0.1, 0.2, 0.3, 1.0, 2.0, 3.0, 0.4, -0.5, 0.05 });
}

/// "crane": 2 dofs (fixed base: mast_yaw, boom_out).
inline diff_rigid_body::BodyModel crane()
{
  using diff_rigid_body::JointType;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  return articulated("crane",
                     {
                         { "mast", -1, "mast_yaw", JointType::Revolute, { 1, 0, 0 }, zero, { 0, 0, 1 }, 0, 1.0, 0.0,
                           5.0, 3 },
                         { "boom", 0, "boom_out", JointType::Prismatic, { 0, 0, 2 }, zero, { 1, 0, 0 }, 1, 1.0, 0.0,
                           1.0, 2 },
                     },
                     { "mast_yaw", "boom_out" }, { 0.7, 0.25 });
}

/// The scene of the header comment; `arm_body` and `crane_body` replace the defaults.
inline diff_rigid_body::Scene scene(diff_rigid_body::BodyModel arm_body = arm(),
                                    diff_rigid_body::BodyModel crane_body = crane())
{
  urdf::TwoBodies free_bodies;
  free_bodies.cube_rpy = "0.1 0.2 0.3";
  diff_rigid_body::Scene result = diff_rigid_body::loadSceneFromUrdf(urdf::twoBodies(free_bodies));
  result.bodies.push_back(std::move(arm_body));
  result.bodies.push_back(std::move(crane_body));
  return result;
}
}  // namespace plumbing
}  // namespace drb_test
