// The model of one body: what never changes after loading (docs/interface.md,
// "Version 2"), built once from the URDF (urdf_scene.h). What every query
// writes lives apart, in a BodyWorkspace (body_workspace.h); the algorithms
// (kinematics.h, crba.h, mass_matrix_derivatives.h, vertex_jacobians.h,
// vertex_backprop.h) are free functions of both.
//
// A body is a tree of segments. A segment is one moving URDF link with every
// link fixed to it merged in (composite mass properties, vertices in the
// segment frame). The root segment hangs on a free joint or on a 1-dof
// joint below a static link (a fixed-base root); every other segment on a
// revolute, continuous or prismatic joint of its parent.
//
// Coordinates x of a body (d = len(x)):
//   free root:       x = (phi, theta, psi, tx, ty, tz, j_0, ..., j_{n-1}),
//                    the RPY angles of the root link's axes and its COM in
//                    the fixed frame, exactly as a version-1 body's q;
//   fixed-base root: x = (j_0, ..., j_{n-1}).
// j_k is the k-th independent joint in URDF document order [rad or m]. A
// mimic joint takes multiplier x[coordinate] + offset and adds no coordinate.
//
// Segment frames. A joint segment's frame is its link frame. A free root's
// frame has the link's axes and its origin at the segment's COM, so that
// its pose is (R(phi, theta, psi), t); its link origin sits at link_origin =
// -COM in that frame. Joint placements below it are folded into the same
// frame at load.
//
// Dofs and motion coordinates. Every coordinate enters through one or more
// dofs, 1-dof motions in a tree (MuJoCo's dof_parentid): one per joint, and
// six for a free root, in the chain order tx, ty, tz, wx, wy, wz
// (translations of the COM, then rotations about the fixed frame's axes
// through the COM). A dof moves its segment and that segment's subtree; its
// parent is the dof just above it on the path to the root. The algorithms
// walk these parent arrays, so their work follows the depth of the tree,
// never segments x coordinates.
//
// The algorithms run in motion coordinates nu (velocities) rather than x':
// a dof's velocity is multiplier nu[coordinate], where nu = x' except for a
// free root's first three, its angular velocity w = T(x_r) x_r' in the fixed
// frame (free_root_chart.h). The Euler-angle chart enters only at the edge
// (motion_coordinates.h), so nothing inside divides by cos(theta).
//
// A free root's three rotations form one joint block: their axes are fixed
// in the fixed frame, so moving one does not carry the others (in a chain
// of 1-dof joints each dof carries every dof below it). Dof::carrier and
// Dof::block_last say so; for every other dof they are its parent and
// itself.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "diff_rigid_body/mass/mass_property_checks.h"
#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
enum class JointType : std::uint8_t
{
  Free,       ///< a free root: six coordinates (phi, theta, psi, tx, ty, tz)
  Revolute,   ///< revolute and continuous: rotation about the axis [rad]
  Prismatic,  ///< translation along the axis [m]
};

/// The kernels a body's algorithms take, chosen once by the model builder
/// (body_builder.cpp). A body of one free segment (a version-1 free object)
/// has closed forms (free_body/: pose, M and dM/dx batched, J and backprop
/// by SIMD kernels) that give the tree's answers to rounding, faster; every
/// other body takes the tree's (one-segment kernels inside them are the
/// same for every segment).
enum class BodyKernels : std::uint8_t
{
  Tree,
  FreeSegment,
};

/// One 1-dof motion of the tree (see the header comment).
struct Dof
{
  int parent = -1;        ///< the dof just above it on the path to the root; -1 for none
  int segment = 0;        ///< the segment it moves, with that segment's subtree
  int coordinate = 0;     ///< index into x and into nu
  double multiplier = 1;  ///< its velocity is multiplier nu[coordinate] (mimic joints; 1 otherwise)
  /// The dof whose motion carries its axis (-1: the fixed frame): its parent,
  /// except for a free root's rotations, whose axes go with the COM (tz).
  int carrier = -1;
  /// The last dof of its joint block: the dofs in (this, block_last] share
  /// its segment and are not carried by it. Itself but for a free root's rotations.
  int block_last = 0;
};

/// One moving link with the links fixed to it.
struct Segment
{
  std::string link;   ///< URDF link name
  std::string joint;  ///< URDF joint that moves it (the floating joint of a free root)
  int parent = -1;    ///< parent segment; -1 for the root
  JointType joint_type = JointType::Revolute;
  /// The joint frame in the parent segment's frame; for a fixed-base root in
  /// the fixed frame; identity for a free root. p_parent = R p_joint + p.
  Eigen::Matrix3d placement_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d placement_translation = Eigen::Vector3d::Zero();
  bool placement_rotates = false;  ///< placement_rotation is not exactly the identity
  /// Unit joint axis, joint-frame axes, and k when it is exactly +-e_k (then
  /// a rotation about it changes two columns of the frame), else -1.
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  int axis_index = -1;
  /// Joint value = multiplier x[coordinate] + offset, the multiplier being
  /// its dof's (mimic joints; offset 0 otherwise) [rad or m].
  double offset = 0.0;
  /// Its dofs: [first_dof, first_dof + dof_count); 6 for a free root (tx,
  /// ty, tz, wx, wy, wz), else 1.
  int first_dof = 0;
  int dof_count = 1;
  /// Composite mass properties of its links in the segment frame (COM 0
  /// exactly for a free root).
  MassProperties inertia;
  /// The URDF link frame's origin in the segment frame (same axes): -COM for
  /// a free root, zero otherwise [m].
  Eigen::Vector3d link_origin = Eigen::Vector3d::Zero();
  /// A revolute joint's slot in the angles whose sines and cosines are taken
  /// together (kinematics.h); -1 otherwise.
  int angle_slot = -1;
  /// Its vertices: BodyModel::vertices columns [vertex_begin, vertex_begin + vertex_count).
  std::uint32_t vertex_begin = 0;
  std::uint32_t vertex_count = 0;
  /// max |p0| over its vertices, in its frame [m] (0 without vertices).
  double vertex_radius = 0.0;
};

/// A URDF link of a body (its segment's own link, or one merged into it).
struct LinkInBody
{
  std::string name;
  std::size_t segment = 0;  ///< index of its segment
  /// Its pose in the segment's link frame (identity for the segment's own link).
  Eigen::Isometry3d pose_in_segment_link = Eigen::Isometry3d::Identity();
  /// Indices into BodyModel::vertices of its own geometry's vertices, in its geometry order.
  std::vector<std::uint32_t> vertex_indices;
  /// How many of the body's vertices start at this link: the links' new
  /// vertices are contiguous, in link order.
  std::uint32_t new_vertex_count = 0;
  /// Its own mass properties in its link frame; zero for a massless link.
  MassProperties mass_properties;
};

/// Everything about one body that never changes after loading.
struct BodyModel
{
  std::string name;        ///< the root segment's link
  std::string joint_name;  ///< the URDF joint that made its root link a body
  std::string joint_type;  ///< that joint's URDF type ("floating", "revolute", ...)
  /// Segments in URDF document order of their links, a parent always before
  /// its children; segments[0] is the root.
  std::vector<Segment> segments;
  /// Dofs, a parent always before its children (free-root dofs first).
  std::vector<Dof> dofs;
  std::size_t coordinates = 0;  ///< d = len(x)
  /// M's factorization order (tree_factorization.h): row k is coordinate
  /// factor_coordinate[k], eliminated into row factor_parent[k] (-1: none).
  /// The dof tree when every coordinate has one dof; a dense chain with mimic joints.
  std::vector<int> factor_coordinate;
  std::vector<int> factor_parent;
  /// The revolute segments, in their angle slots; a free root's phi, theta,
  /// psi take the three slots after them.
  std::vector<int> revolute_segments;
  /// Every vertex in its segment's frame [m], one per column; each segment's
  /// are contiguous. vertex_columns holds the same by coordinate (N x 3),
  /// the layout of the backprop's sums.
  Matrix3X<double> vertices;
  VertexColumns<double> vertex_columns;
  /// Links in vertex order: segment after segment, each its own link first,
  /// then its merged links in document order.
  std::vector<LinkInBody> links;
  /// The independent joints in x order (after a free root's 6) and their
  /// limits [rad or m]; -inf / +inf where the URDF gives none.
  std::vector<std::string> joint_names;
  std::vector<double> joint_lower;
  std::vector<double> joint_upper;
  /// x at load: the free root's pose from the URDF joint origins, every joint at 0.
  Eigen::VectorXd initial_x;
  BodyKernels kernels = BodyKernels::Tree;  ///< set by the builder

  bool hasFreeRoot() const { return segments.front().joint_type == JointType::Free; }
  /// Whether the algorithms take the closed forms of one free segment (kernels).
  bool closedFormKernels() const { return kernels == BodyKernels::FreeSegment; }
  /// Coordinates of the root: 6 for a free root, else 0.
  std::size_t rootCoordinates() const { return hasFreeRoot() ? 6 : 0; }
  std::size_t vertexCount() const { return static_cast<std::size_t>(vertices.cols()); }
  /// Total mass [kg].
  double mass() const;
  /// The root link's COM in its link frame [m] (get_bodies' com_offsets).
  Eigen::Vector3d rootComOffset() const { return segments.front().inertia.com - segments.front().link_origin; }
  /// Index of the segment that owns vertex `v` (< vertexCount()).
  std::size_t segmentOfVertex(std::uint32_t v) const;
};

}  // namespace diff_rigid_body
