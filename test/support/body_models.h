// The core's body model (include/diff_rigid_body/multibody/body_model.h) from the
// tests' side: models built by hand (the fields the URDF loader derives,
// derived as the loader does: its dofs by its own buildDofs), and the
// algorithms called with a workspace of their own, returning values.
//
// Not an oracle: the numbers come from the core (crba.h, kinematics.h, ...).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/multibody/body_model.h"
#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/kinematics.h"
#include "diff_rigid_body/algorithm/mass_matrix_derivatives.h"
#include "diff_rigid_body/algorithm/vertex_backprop.h"
#include "diff_rigid_body/algorithm/vertex_jacobians.h"
#include "../../src/core/parsers/body_coordinates.h"  // buildDofs: the loader's dofs of a hand-made model

namespace drb_test
{
namespace core_body
{
namespace drb = diff_rigid_body;

template <typename Scalar>
using MatrixX = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
using RowMajorMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// ---------------------------------------------------------------------------
// Hand-made models.

/// How a joint segment's value follows x (src/core/parsers/body_coordinates.h): multiplier x[coordinate] + offset.
using JointCoordinate = drb::detail::JointCoordinate;

/// Derives what follows from a model's primary fields (segments' link,
/// joint, parent, joint_type, placement, axis, inertia, link_origin and
/// vertex ranges; vertices; joint_names): each segment's axis_index,
/// placement_rotates and vertex_radius, vertex_columns, and everything of
/// the dofs (dofs, first_dof, dof_count, offset, coordinates and what the
/// loader derives from them) by the loader's own buildDofs, from
/// `coordinates` (one per segment; a free root's unused).
inline void deriveFields(drb::BodyModel& body, const std::vector<JointCoordinate>& coordinates)
{
  for (drb::Segment& segment : body.segments)
  {
    segment.axis_index = -1;
    for (int k = 0; k < 3; ++k)
      if (std::abs(segment.axis[k]) == 1.0 && segment.axis[(k + 1) % 3] == 0.0 && segment.axis[(k + 2) % 3] == 0.0)
        segment.axis_index = k;
    segment.placement_rotates =
        !(segment.placement_rotation.array() == Eigen::Matrix3d::Identity().array()).all();
    segment.vertex_radius =
        segment.vertex_count ?
            body.vertices.middleCols(segment.vertex_begin, segment.vertex_count).colwise().norm().maxCoeff() :
            0.0;
  }
  body.vertex_columns = body.vertices.transpose();
  drb::detail::buildDofs(coordinates, body);
}

/// deriveFields again after a change, each joint segment keeping its
/// current coordinate, multiplier and offset.
inline void refreshDerivedFields(drb::BodyModel& body)
{
  std::vector<JointCoordinate> coordinates(body.segments.size());
  for (std::size_t s = 0; s < body.segments.size(); ++s)
  {
    const drb::Segment& segment = body.segments[s];
    if (segment.joint_type == drb::JointType::Free)
      continue;
    const drb::Dof& dof = body.dofs[static_cast<std::size_t>(segment.first_dof)];
    coordinates[s] = { dof.coordinate, dof.multiplier, segment.offset };
  }
  deriveFields(body, coordinates);
}

/// Appends the link of the segment about to be appended (its own link only,
/// no merged links): its vertex range, and its mass properties `in_link` in
/// its link frame.
inline void addSegmentLink(drb::BodyModel& body, const drb::Segment& segment, const drb::MassProperties& in_link)
{
  drb::LinkInBody link;
  link.name = segment.link;
  link.segment = body.segments.size();
  link.new_vertex_count = segment.vertex_count;
  for (std::uint32_t v = 0; v < segment.vertex_count; ++v)
    link.vertex_indices.push_back(segment.vertex_begin + v);
  link.mass_properties = in_link;
  body.links.push_back(link);
}

/// A free object: one free segment of mass `mass` and inertia `inertia`
/// about its COM, `vertices` in its frame (origin at the COM), its link
/// origin at -`com_offset`; x at load = `initial` (6 values).
inline drb::BodyModel freeObject(const std::string& name, double mass, const Eigen::Matrix3d& inertia,
                                 const Eigen::Matrix3Xd& vertices,
                                 const Eigen::Vector3d& com_offset = Eigen::Vector3d::Zero(),
                                 const Eigen::VectorXd& initial = Eigen::VectorXd::Zero(6))
{
  drb::BodyModel body;
  body.name = name;
  drb::Segment segment;
  segment.link = name;
  segment.joint_type = drb::JointType::Free;
  segment.inertia.mass = mass;
  segment.inertia.inertia = inertia;
  segment.link_origin = -com_offset;
  segment.vertex_count = static_cast<std::uint32_t>(vertices.cols());
  drb::MassProperties in_link = segment.inertia;
  in_link.com = com_offset;
  addSegmentLink(body, segment, in_link);
  body.segments.push_back(segment);
  body.vertices = vertices;
  body.initial_x = initial;
  deriveFields(body, std::vector<JointCoordinate>(1));
  return body;
}

// ---------------------------------------------------------------------------
// The algorithms, each in a workspace of its own.

/// M(x) by the composite-rigid-body algorithm (crba.h).
template <typename Scalar>
MatrixX<Scalar> massMatrixAt(const drb::BodyModel& model, const Scalar* x)
{
  drb::BodyWorkspace<Scalar> ws(model);
  drb::crba(model, ws, x);
  return ws.M;
}

/// dM/dx_j, j = 0..d-1, each d x d (mass_matrix_derivatives.h).
inline std::vector<Eigen::MatrixXd> massMatrixDerivativesAt(const drb::BodyModel& model, const double* x)
{
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  drb::BodyWorkspace<double> ws(model);
  std::vector<double> values(static_cast<std::size_t>(d * d * d));
  drb::massMatrixDerivatives(model, ws, x, values.data());
  std::vector<Eigen::MatrixXd> dM;
  for (Eigen::Index j = 0; j < d; ++j)
    dM.emplace_back(Eigen::Map<const RowMajorMatrixXd>(values.data() + j * d * d, d, d));
  return dM;
}

/// Forward kinematics at x in a workspace of its own (kinematics.h).
template <typename Scalar>
drb::BodyWorkspace<Scalar> kinematicsAt(const drb::BodyModel& model, const Scalar* x)
{
  drb::BodyWorkspace<Scalar> ws(model);
  drb::forwardKinematics(model, ws, x);
  return ws;
}

/// Vertex v in the fixed frame from the kinematics in ws: R_s p0 + p_s.
template <typename Scalar>
drb::Vector3<Scalar> vertexPosition(const drb::BodyModel& model, const drb::BodyWorkspace<Scalar>& ws, std::uint32_t v)
{
  const std::size_t s = model.segmentOfVertex(v);
  return ws.R[s] * model.vertices.col(v).template cast<Scalar>() + ws.p[s];
}

/// Vertex v in its segment's URDF link frame: p0 - link_origin.
inline Eigen::Vector3d vertexInLinkFrame(const drb::BodyModel& model, std::uint32_t v)
{
  return model.vertices.col(v) - model.segments[model.segmentOfVertex(v)].link_origin;
}

/// Positions and the written J columns of `vertices` (empty = all) at x
/// (vertex_jacobians.h; `compact`: JacobianColumns::compact, else all).
inline void vertexJacobiansAt(const drb::BodyModel& model, bool compact, const std::vector<std::uint32_t>& vertices,
                              const double* x, double* positions, double* jacobians)
{
  drb::BodyWorkspace<double> ws(model);
  const drb::JacobianColumns columns =
      compact ? drb::JacobianColumns::compact(model) : drb::JacobianColumns::all(model);
  drb::vertexJacobians<double>(model, ws, columns, vertices, x, positions, jacobians);
}

/// dL/dx for gradients g (3 per vertex of `vertices`, empty = all) at x (vertex_backprop.h).
inline void backpropAt(const drb::BodyModel& model, const std::vector<std::uint32_t>& vertices, const double* g,
                       const double* x, double* gradient)
{
  drb::BodyWorkspace<double> ws(model);
  drb::vertexBackprop(model, ws, vertices, g, x, gradient);
}

}  // namespace core_body
}  // namespace drb_test
