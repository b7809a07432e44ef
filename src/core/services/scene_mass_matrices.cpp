// SceneQueries::massMatrices: the request's checks and layout, and M(x) and
// dM/dx per body (crba.h, mass_matrix_derivatives.h).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "diff_rigid_body/algorithm/crba.h"
#include "diff_rigid_body/algorithm/mass_matrix_derivatives.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "services/request_checks.h"
#include "services/request_layout.h"

namespace diff_rigid_body
{
using detail::reject;
using detail::sizeMismatch;

void SceneQueries::massMatrices(const SceneState& current, const std::vector<std::string>& bodies,
                                DoubleView q, bool derivatives, MassMatrixAnswer& answer) const
{
  thread_local std::vector<std::size_t> indices;  // reused: no allocation per call in steady state
  bodyIndices(bodies, "bodies", indices);
  const std::size_t n = indices.size();
  const detail::RequestLayout& layout = detail::requestLayout(*this, indices);
  std::size_t configurations = 1;
  if (!q.empty())
  {
    if (n == 0 || q.size() % layout.D != 0)
      reject(sizeMismatch("q",
                          layout.all_six ? "a multiple of 6 x " + std::to_string(n) +
                                                " bodies (or empty for the current state)" :
                                            "a multiple of " + std::to_string(layout.D) + " values (the sum of the " +
                                                std::to_string(n) + " bodies' dofs), or empty for the current state",
                          q.size()));
    configurations = q.size() / layout.D;
    requireFinite(q.data(), q.size(), "q");
  }
  checkMassMatrixBudget(configurations, n, layout.per_m + (derivatives ? layout.per_dm : 0), layout.all_six,
                        derivatives, q.size());
  MassMatrixAnswer result = std::move(answer);
  result.bodies.resize(n);
  result.dofs.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    result.bodies[i] = scene_.bodies[indices[i]].name;
    result.dofs[i] = static_cast<std::uint32_t>(dofs(indices[i]));
  }
  result.mass_matrices.resize(configurations * layout.per_m);
  result.cos_theta.resize(configurations * n);
  result.derivatives.resize(derivatives ? configurations * layout.per_dm : 0);
  // Body i's x: q + x_offset[i], D apart, or its current state; matrix (k, i)
  // at k per_m + m_offset[i], cos_theta (k n + i). With derivatives, M and
  // dM/dx of one configuration from one CRBA; without, each body's K
  // configurations in one batch.
  const auto bodyQ = [&](std::size_t k, std::size_t i) {
    return q.empty() ? current[indices[i]].data() : q.data() + k * layout.D + layout.x_offset[i];
  };
  if (!derivatives)
    for (std::size_t i = 0; i < n; ++i)
      diff_rigid_body::massMatrices(scene_.bodies[indices[i]], workspace(indices[i]), bodyQ(0, i), configurations,
                                    layout.D, layout.per_m, n, result.mass_matrices.data() + layout.m_offset[i],
                                    result.cos_theta.data() + i);
  else
    for (std::size_t k = 0; k < configurations; ++k)
      for (std::size_t i = 0; i < n; ++i)
      {
        const BodyModel& body = scene_.bodies[indices[i]];
        BodyWorkspace<double>& ws = workspace(indices[i]);
        diff_rigid_body::massMatrices(body, ws, bodyQ(k, i), 1, layout.D, layout.per_m, n,
                                      result.mass_matrices.data() + k * layout.per_m + layout.m_offset[i],
                                      result.cos_theta.data() + k * n + i);
        massMatrixDerivativesRowMajor(body, ws, bodyQ(k, i),
                                      result.derivatives.data() + k * layout.per_dm + layout.dm_offset[i],
                                      /*crba_done=*/true);
      }
  // Finite inputs can still overflow (e.g. an inertia near DBL_MAX): never
  // return a non-finite number silently.
  detail::requireFiniteResults(
      { { "result mass_matrices", &result.mass_matrices }, { "result derivatives", &result.derivatives } });
  answer = std::move(result);
}

MassMatrixAnswer SceneQueries::massMatrices(const SceneState& current, const std::vector<std::string>& bodies,
                                            DoubleView q, bool derivatives) const
{
  MassMatrixAnswer answer;
  massMatrices(current, bodies, q, derivatives, answer);
  return answer;
}

void SceneQueries::checkMassMatrixBudget(std::size_t configurations, std::size_t bodies, std::size_t per_configuration,
                                         bool all_six, bool derivatives, std::size_t q_size) const
{
  // For 6-dof bodies per_configuration = 36 n (252 n with derivatives), so
  // this is "configurations x bodies <= kMaxMassMatrices(WithDerivatives)".
  const std::size_t budget =
      derivatives ? RequestLimits::kMaxMassMatrixDoublesWithDerivatives : RequestLimits::kMaxMassMatrixDoubles;
  if (detail::withinBudget(configurations, per_configuration, budget))
    return;
  if (all_six)
  {
    const std::size_t limit =
        derivatives ? RequestLimits::kMaxMassMatricesWithDerivatives : RequestLimits::kMaxMassMatrices;
    reject(sizeMismatch("q", "at most " + std::to_string(limit) + " matrices (configurations x bodies), i.e. " +
                                 std::to_string(limit * 6) + " values",
                        q_size));
  }
  std::ostringstream why;
  why << "q: expected at most " << budget << " answer values (configurations x the sum over the " << bodies
      << " bodies of dof^2" << (derivatives ? " + dof^3" : "") << "), got " << configurations << " x "
      << per_configuration;
  reject(why.str());
}

}  // namespace diff_rigid_body
