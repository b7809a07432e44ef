// The coordinates of a body's joints (internal to the core): independent
// joints in URDF document order, mimic joints following their masters, and
// the dofs of the body model (body_model.h) built from them.
#pragma once

#include <vector>

#include "diff_rigid_body/multibody/body_model.h"
#include "parsers/rigid_group.h"
#include "parsers/urdf_model.h"

namespace diff_rigid_body
{
namespace detail
{
/// How a joint segment's value follows x: multiplier x[coordinate] + offset.
struct JointCoordinate
{
  int coordinate = -1;
  double multiplier = 1.0;
  double offset = 0.0;
};

/// Per segment of `body` (its segments and joints set; a free root's entry
/// unused): the coordinate of each independent joint, numbered in document
/// order after the root's body.rootCoordinates(), and the composed
/// multiplier and offset of each mimic joint's chain of masters. Fills
/// body.joint_names, joint_lower and joint_upper. A mimic whose master is
/// not another 1-dof joint of the body is independent, with a warning; a
/// circular chain throws SceneDescriptionError.
std::vector<JointCoordinate> assignCoordinates(const UrdfDescription& description, BodyModel& body,
                                               LoadContext& context);

/// body.dofs and each segment's first_dof, dof_count and offset from the
/// coordinates (a free root's six dofs first, in the chain order tx, ty, tz,
/// psi, theta, phi); body.coordinates; the factorization order of M.
void buildDofs(const std::vector<JointCoordinate>& coordinates, BodyModel& body);

/// Warns (refuses with ~strict_inertia) about a joint whose subtree has no
/// mass, and a free root with no mass at all: M(x) is singular there.
void warnIfCoordinatesMoveNoMass(const BodyModel& body, LoadContext& context);

}  // namespace detail
}  // namespace diff_rigid_body
