#include "diff_rigid_body/multibody/body_model.h"

#include <algorithm>

namespace diff_rigid_body
{
double BodyModel::mass() const
{
  double total = 0.0;
  for (const Segment& segment : segments)
    total += segment.inertia.mass;
  return total;
}

std::size_t BodyModel::segmentOfVertex(std::uint32_t v) const
{
  // Segments' vertex ranges are contiguous and in segment order.
  const auto after = std::upper_bound(segments.begin(), segments.end(), v,
                                      [](std::uint32_t vertex, const Segment& s) { return vertex < s.vertex_begin; });
  return static_cast<std::size_t>(after - segments.begin()) - 1;
}

}  // namespace diff_rigid_body
