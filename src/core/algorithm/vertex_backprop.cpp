#include "diff_rigid_body/algorithm/vertex_backprop.h"

#include <algorithm>

#include "diff_rigid_body/algorithm/detail/backprop_sums.h"
#include "diff_rigid_body/algorithm/free_body/vertex_columns.h"
#include "diff_rigid_body/algorithm/kinematics.h"
#include "diff_rigid_body/multibody/motion_coordinates.h"

namespace diff_rigid_body
{
namespace
{
/// outer = sum g p0^T and force = sum g per segment (ws.segment_sums).
void segmentGradientSums(const BodyModel& model, BodyWorkspace<double>& ws,
                         const std::vector<std::uint32_t>& vertices, const double* gradients)
{
  for (auto& sums : ws.segment_sums)
    sums = BodyWorkspace<double>::SegmentSums();
  if (!vertices.empty())
  {
    for (std::size_t k = 0; k < vertices.size(); ++k)
    {
      auto& sums = ws.segment_sums[model.segmentOfVertex(vertices[k])];
      const Eigen::Map<const Eigen::Vector3d> g(gradients + 3 * k);
      sums.force += g;
      sums.outer.noalias() += g * model.vertices.col(vertices[k]).transpose();
    }
    return;
  }
  const detail::ByCoordinate all = detail::byCoordinate(model.vertex_columns);
  for (std::size_t s = 0; s < model.segments.size(); ++s)
  {
    const Segment& segment = model.segments[s];
    const VertexGradientSums sums(detail::gradientSums(
        all.from(segment.vertex_begin), detail::ByVertex{ gradients + 3 * std::size_t(segment.vertex_begin) },
        segment.vertex_count));
    ws.segment_sums[s].outer = sums.W;
    ws.segment_sums[s].force = sums.force;
  }
}
}  // namespace

bool vertexBackprop(const BodyModel& model, BodyWorkspace<double>& ws, const std::vector<std::uint32_t>& vertices,
                    const double* gradients, const double* x, double* gradient)
{
  if (model.closedFormKernels())
  {
    const BodyPose<double> pose{ Eigen::Map<const Vector6<double>>(x) };
    const Vector6<double> dL_dq = backpropagateVertexGradients(pose, model.vertex_columns, vertices, gradients);
    std::copy(dL_dq.data(), dL_dq.data() + 6, gradient);
    return true;
  }
  forwardKinematics(model, ws, x);
  if (!kinematicsAreFinite(model, ws))
    return false;
  segmentGradientSums(model, ws, vertices, gradients);
  const std::size_t n = model.segments.size();
  for (std::size_t s = 0; s < n; ++s)
  {
    auto& sums = ws.segment_sums[s];
    const Eigen::Matrix3d A = sums.outer * ws.R[s].transpose();
    sums.moment = Eigen::Vector3d(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1)) +
                  (ws.p[s] - ws.r).cross(sums.force);
  }
  for (std::size_t s = n; s-- > 1;)  // subtree sums: children after their parents
  {
    auto& parent = ws.segment_sums[static_cast<std::size_t>(model.segments[s].parent)];
    parent.force += ws.segment_sums[s].force;
    parent.moment += ws.segment_sums[s].moment;
  }
  std::fill(gradient, gradient + model.coordinates, 0.0);
  for (std::size_t k = 0; k < model.dofs.size(); ++k)
  {
    const Dof& dof = model.dofs[k];
    const auto& sums = ws.segment_sums[static_cast<std::size_t>(dof.segment)];
    gradient[dof.coordinate] += dof.multiplier * (ws.S[k].v.dot(sums.force) + ws.S[k].w.dot(sums.moment));
  }
  forceToCoordinates(model, ws, gradient);  // dL/dx = A^T dL/dnu
  return true;
}

}  // namespace diff_rigid_body
