// Where each listed body's values sit in a multi-body request and answer
// (get_mass_matrix, inverse_dynamics, forward_dynamics, get_center_of_mass),
// and the checks those requests share; internal to the core.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include <initializer_list>
#include <sstream>
#include <string>
#include <utility>

#include "diff_rigid_body/services/scene_queries.h"
#include "services/request_checks.h"

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

/// The K of a dynamics request on `bodies` bodies of D coordinates in all: from q (K D values;
/// empty = 1), with each other array of q's length (K D) or empty, every value finite.
inline std::size_t dynamicsConfigurations(std::size_t D, std::size_t bodies,
                                   DoubleView q,
                                   std::initializer_list<std::pair<const char*, const DoubleView*>> others)
{
  // K = q.size() / D; one configuration, the usual call, needs no division.
  const std::size_t configurations = q.empty() || q.size() == D ? 1 : D == 0 ? 0 : q.size() / D;
  if (!q.empty() && (bodies == 0 || configurations * D != q.size()))
    detail::reject(detail::sizeMismatch("q",
                        "a multiple of " + std::to_string(D) + " values (the sum of the " +
                            std::to_string(bodies) + " bodies' dofs), or empty for the current state",
                        q.size()));
  requireFinite(q.data(), q.size(), "q");
  for (const auto& [field, values] : others)
  {
    if (!values->empty() && values->size() != configurations * D)
      detail::reject(detail::sizeMismatch(field,
                          std::to_string(configurations * D) + " values (q's " + std::to_string(configurations) +
                              " configuration(s) x " + std::to_string(D) + "), or empty for zeros",
                          values->size()));
    if (!values->empty())
      requireFinite(values->data(), values->size(), field);
  }
  return configurations;
}

/// The bodies of a multi-body batched request (get_mass_matrix's layout):
/// their scene indices (this thread's buffer, valid until its next request),
/// where each one's values sit, and K.
struct BatchedBodies
{
  const std::vector<std::size_t>& indices;
  const RequestLayout& layout;
  std::size_t K;
};

/// Resolves `names` (empty = all; unknown ones refused by name), lays them
/// out, and checks q and `others` as dynamicsConfigurations.
inline BatchedBodies batchedBodies(const SceneQueries& queries, const std::vector<std::string>& names, DoubleView q,
                                   std::initializer_list<std::pair<const char*, const DoubleView*>> others)
{
  thread_local std::vector<std::size_t> indices;
  queries.bodyIndices(names, "bodies", indices);
  const RequestLayout& layout = requestLayout(queries, indices);
  return { indices, layout, dynamicsConfigurations(layout.D, indices.size(), q, others) };
}

/// Whether `configurations` x `per_configuration` answer values fit in
/// `budget` (a product that overflows does not).
inline bool withinBudget(std::size_t configurations, std::size_t per_configuration, std::size_t budget)
{
  std::size_t values = 0;
  return !__builtin_mul_overflow(configurations, per_configuration, &values) && values <= budget;
}

/// Refuses an answer of more doubles than the budget of get_mass_matrix
/// (with matrices: its budget with derivatives).
inline void checkDynamicsBudget(std::size_t configurations, std::size_t per_configuration, bool matrices)
{
  const std::size_t budget =
      matrices ? RequestLimits::kMaxMassMatrixDoublesWithDerivatives : RequestLimits::kMaxMassMatrixDoubles;
  if (withinBudget(configurations, per_configuration, budget))
    return;
  std::ostringstream why;
  why << "q: expected at most " << budget << " answer values, got " << configurations << " configuration(s) x "
      << per_configuration << " values";
  detail::reject(why.str());
}

template <typename Answer>
inline void setBodies(const SceneQueries& queries, const std::vector<std::size_t>& indices, Answer& answer)
{
  answer.bodies.resize(indices.size());
  answer.dofs.resize(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i)
  {
    answer.bodies[i] = queries.body(indices[i]).name;
    answer.dofs[i] = static_cast<std::uint32_t>(queries.dofs(indices[i]));
  }
}

/// One slot of a batched multi-body answer: configuration k, listed body i.
struct BodySlot
{
  std::size_t body;  ///< the body's index in the scene
  std::size_t n;     ///< k n_bodies + i: the slot's index among the answer's slots
  std::size_t v;     ///< k D + x_offset[i]: where its vectors (x, x', tau, ...) start
  std::size_t m;     ///< k per_m + m_offset[i]: where its d x d matrices start
  const double* x;   ///< its d coordinates: q + v, or the current state when q is empty
};

/// Calls visit(slot) for every configuration k < K and listed body i, in
/// the answer's order (configuration-major), and sets cos_theta (K n
/// values): cos(theta) of a free root (0 at gimbal lock), 1 for a fixed base.
template <typename Visit>
void forEachBodySlot(const SceneQueries& queries, const RequestLayout& layout, const std::vector<std::size_t>& indices,
                     std::size_t K, const SceneState& current, DoubleView q,
                     std::vector<double>& cos_theta, Visit&& visit)
{
  const std::size_t n = indices.size();
  cos_theta.resize(K * n);
  for (std::size_t k = 0; k < K; ++k)
    for (std::size_t i = 0; i < n; ++i)
    {
      const std::size_t v = k * layout.D + layout.x_offset[i];
      const BodySlot slot{ indices[i], k * n + i, v, k * layout.per_m + layout.m_offset[i],
                           q.empty() ? current[indices[i]].data() : q.data() + v };
      visit(slot);
      cos_theta[slot.n] = queries.body(slot.body).hasFreeRoot() ? std::cos(slot.x[THETA]) : 1.0;
    }
}

/// Refuses an answer with a value that is not finite, naming its field and index
/// (finite_values.cpp: one pass over all the fields when they are finite).
void requireFiniteResults(std::initializer_list<std::pair<const char*, const std::vector<double>*>> results);

inline const double* slice(DoubleView values, std::size_t offset)
{
  return values.empty() ? nullptr : values.data() + offset;
}
}  // namespace detail
}  // namespace diff_rigid_body
