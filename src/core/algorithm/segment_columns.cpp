#include "algorithm/segment_columns.h"

#include <algorithm>

namespace diff_rigid_body
{
namespace detail
{
void prepareSegmentColumns(const BodyModel& model, BodyWorkspace<double>& ws, const JacobianColumns& columns,
                           std::size_t s)
{
  const std::size_t width = columns.width;
  double* rows = ws.column_motion.data();
  std::fill(rows, rows + 6 * width, 0.0);
  const Segment& segment = model.segments[s];
  for (int k = segment.first_dof + segment.dof_count - 1; k >= 0; k = model.dofs[static_cast<std::size_t>(k)].parent)
  {
    const Dof& dof = model.dofs[static_cast<std::size_t>(k)];
    const int column = columns.of_coordinate[static_cast<std::size_t>(dof.coordinate)];
    if (column < 0)
      continue;
    const Motion<double>& S = ws.S[static_cast<std::size_t>(k)];
    for (int i = 0; i < 3; ++i)
    {
      rows[i * width + static_cast<std::size_t>(column)] += dof.multiplier * S.v[i];
      rows[(3 + i) * width + static_cast<std::size_t>(column)] += dof.multiplier * S.w[i];
    }
  }
  if (!model.hasFreeRoot())
    return;
  const Matrix3<double>& T = ws.chart.T;
  const std::size_t c0 = static_cast<std::size_t>(columns.of_coordinate[0]);  // rotation columns are always written
  for (int i = 0; i < 6; ++i)
  {
    double* row = rows + static_cast<std::size_t>(i) * width + c0;
    const double along[3] = { row[0], row[1], row[2] };
    for (int c = 0; c < 3; ++c)
      row[c] = along[0] * T(0, c) + along[1] * T(1, c) + along[2] * T(2, c);
  }
}

}  // namespace detail
}  // namespace diff_rigid_body
