// Where each listed body's values sit in a multi-body request and answer
// (get_mass_matrix, inverse_dynamics, forward_dynamics); internal to the core.
#pragma once

#include <cstddef>
#include <vector>

#include "diff_rigid_body/scene_queries.h"

namespace diff_rigid_body
{
namespace detail
{
/// Per configuration: body i's x (and every vector) at x_offset[i] of D
/// values, its d x d matrices at m_offset[i] of per_m, its d^3 tensors at
/// dm_offset[i] of per_dm.
struct RequestLayout
{
  std::vector<std::size_t> x_offset, m_offset, dm_offset;
  std::size_t D = 0, per_m = 0, per_dm = 0;
  bool all_six = true;  ///< every listed body has 6 coordinates (version 1's messages, in matrices)
};

/// The layout of a request for the bodies `indices`, in this thread's reused buffers.
inline const RequestLayout& requestLayout(const SceneQueries& queries, const std::vector<std::size_t>& indices)
{
  thread_local RequestLayout layout;
  layout.x_offset.clear();
  layout.m_offset.clear();
  layout.dm_offset.clear();
  layout.D = layout.per_m = layout.per_dm = 0;
  layout.all_six = true;
  for (std::size_t index : indices)
  {
    const std::size_t d = queries.dofs(index);
    layout.x_offset.push_back(layout.D);
    layout.m_offset.push_back(layout.per_m);
    layout.dm_offset.push_back(layout.per_dm);
    layout.D += d;
    layout.per_m += d * d;
    layout.per_dm += d * d * d;
    layout.all_six = layout.all_six && d == 6;
  }
  return layout;
}

}  // namespace detail
}  // namespace diff_rigid_body
