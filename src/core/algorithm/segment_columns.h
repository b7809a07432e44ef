// The columns (V_c, W_c) of dp/dx for the points of one segment, for the
// vertex Jacobians (vertex_jacobians.cpp; frame_jacobians.cpp writes the same
// columns of its one point directly). A point p of segment s moves at
//   dp/dx_c = V_c + W_c x (p - r),   (W_c; V_c) = (sum over the dofs k on s's
// path that drive nu_c of m_k S_k) A,
// A the chart (motion_coordinates.h): a free root's three rotation columns
// turned by T. Internal to the core.
#pragma once

#include <cstddef>

#include "diff_rigid_body/multibody/body_workspace.h"
#include "diff_rigid_body/algorithm/vertex_jacobians.h"

namespace diff_rigid_body
{
namespace detail
{
/// Segment s's written columns into ws.column_motion: rows V_x, V_y, V_z,
/// W_x, W_y, W_z, columns.width apart, from the kinematics in ws.
void prepareSegmentColumns(const BodyModel& model, BodyWorkspace<double>& ws, const JacobianColumns& columns,
                           std::size_t s);
}  // namespace detail
}  // namespace diff_rigid_body
