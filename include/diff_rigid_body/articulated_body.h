// An articulated body (interface.md, "Version 2"): a kinematic tree of
// segments joined by 1-dof joints, under a floating or a fixed-base root.
//
// A segment is one moving URDF link with every link fixed to it merged in
// (composite mass properties, vertices in the segment's link frame).
//
// Coordinates x of a body:
//   floating root:   x = (phi, theta, psi, tx, ty, tz, j_0, ..., j_{n-1})
//                    the root segment's RPY angles and its COM in the fixed
//                    frame, as a version-1 free body's q;
//   fixed-base root: x = (j_0, ..., j_{n-1}).
// j_k is the position of the body's k-th independent joint in URDF document
// order [rad for revolute and continuous, m for prismatic]. A mimic joint
// takes multiplier * x[coordinate of its master] + offset and adds no
// coordinate.
//
// Segment kinematics, at joint value s (URDF):
//   X_child = X_parent * origin * motion(s)
//   motion(s) = rotation by s about `axis` (revolute), or translation s axis (prismatic)
// where X is a segment's link-frame pose in the fixed frame, `origin` is the
// joint's <origin> and `axis` its unit <axis>, in joint-frame axes.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "diff_rigid_body/rigid_body.h"
#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
enum class JointMotion
{
  Revolute,  ///< revolute and continuous: rotation about the axis [rad]
  Prismatic  ///< translation along the axis [m]
};

/// One moving link of an articulated body, with the links fixed to it.
struct Segment
{
  std::string link;   ///< URDF link name; its frame is the segment frame
  int parent = -1;    ///< index of the parent segment; -1 for the root
  std::string joint;  ///< URDF joint that moves it; "" for a floating root
  JointMotion motion = JointMotion::Revolute;
  /// The joint's <origin>: joint frame in the parent segment's frame; for a
  /// fixed-base root, in the fixed frame. Identity for a floating root.
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  ///< unit axis, joint axes
  /// x index of the coordinate that drives the joint (the master's for a
  /// mimic joint); -1 for a floating root. Joint value = multiplier x + offset.
  int coordinate = -1;
  double multiplier = 1.0;
  double offset = 0.0;
  /// Composite mass properties of the segment's links, in its frame.
  MassProperties mass_properties;
  /// Its vertices: ArticulatedBody::vertices columns [vertex_begin, vertex_begin + vertex_count).
  std::uint32_t vertex_begin = 0;
  std::uint32_t vertex_count = 0;
};

/// A kinematic tree of segments (see the header comment for x).
struct ArticulatedBody
{
  std::string name;  ///< the root segment's link
  bool floating_root = false;
  /// Segments in URDF document order of their links, except that a parent
  /// always comes before its children; segments[0] is the root.
  std::vector<Segment> segments;
  /// Every vertex in its segment's frame [m]; each segment's are contiguous.
  Matrix3X<double> vertices;
  /// The independent joints, in x order (after the root's 6 when it floats),
  /// and their limits [rad or m]; -inf / +inf where the URDF gives none.
  std::vector<std::string> joint_names;
  std::vector<double> joint_lower;
  std::vector<double> joint_upper;

  /// Number of root coordinates: 6 for a floating root, else 0.
  std::size_t rootCoordinates() const { return floating_root ? 6 : 0; }
  /// len(x).
  std::size_t dofs() const { return rootCoordinates() + joint_names.size(); }
  /// Index of the segment that owns vertex `v`.
  std::size_t segmentOfVertex(std::uint32_t v) const;
};

}  // namespace diff_rigid_body
