#include "diff_rigid_body/scene_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <unordered_set>

#include "diff_rigid_body/exceptions.h"
#include "request_checks.h"
#include "diff_rigid_body/mass_matrix.h"
#include "scene_queries_articulated.h"

namespace diff_rigid_body
{
using detail::reject;
using detail::sizeMismatch;

namespace
{
// Copies a 6x6 matrix row-major into `out`.
void writeRowMajor6(const Matrix6<double>& M, double* out)
{
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> target(out);
  target = M;
}

// M(q_k) and cos(theta_k) of one free body for the states q_k = q + k stride,
// k < count, by massMatrixBatch (mass_matrix.h: vectorised sinCos over
// blocks of states, M written entry by entry). Matrix k goes to
// mass_matrices + k m_stride, its cos_theta to cos_theta[k cos_stride]:
// adjacent slots (m_stride 36, cos_stride 1) are written in place;
// otherwise (several bodies per configuration) blocks of states go through
// an L1 buffer and are copied to their slots.
void bodyMassMatrices(const RigidBody& body, const double* q, std::size_t count, std::size_t stride,
                      std::size_t m_stride, std::size_t cos_stride, double* mass_matrices, double* cos_theta)
{
  if ((m_stride == 36 && cos_stride == 1) || count == 1)
  {
    massMatrixBatch(q, count, stride, body.mass, body.inertia_body, mass_matrices, cos_theta);
    return;
  }
  constexpr std::size_t kBlock = 64;  // 18 KiB of matrices
  double block[36 * kBlock], cos_block[kBlock];
  for (std::size_t k0 = 0; k0 < count; k0 += kBlock)
  {
    const std::size_t m = std::min(kBlock, count - k0);
    massMatrixBatch(q + k0 * stride, m, stride, body.mass, body.inertia_body, block, cos_block);
    for (std::size_t j = 0; j < m; ++j)
    {
      std::copy(block + 36 * j, block + 36 * (j + 1), mass_matrices + (k0 + j) * m_stride);
      cos_theta[(k0 + j) * cos_stride] = cos_block[j];
    }
  }
}
}  // namespace

MassMatrixAnswer SceneQueries::massMatrices(const SceneState& current, const std::vector<std::string>& names,
                                            const std::vector<double>& q, bool derivatives) const
{
  const std::vector<std::size_t> indices = bodyIndices(names, "bodies");
  const std::size_t n = indices.size();
  // Per configuration: body i's x at x_offset[i] of D values, its M at
  // m_offset[i] of per_m, its dM at dm_offset[i] of per_dm.
  std::vector<std::size_t> x_offset(n), m_offset(n), dm_offset(n);
  std::size_t D = 0, per_m = 0, per_dm = 0;
  bool all_free = true;
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t d = dofs(indices[i]);
    x_offset[i] = D;
    m_offset[i] = per_m;
    dm_offset[i] = per_dm;
    D += d;
    per_m += d * d;
    per_dm += d * d * d;
    all_free = all_free && !scene_.bodies[indices[i]].articulated;
  }
  std::size_t configurations = 1;
  if (!q.empty())
  {
    if (n == 0 || q.size() % D != 0)
      reject(sizeMismatch("q",
                          all_free ? "a multiple of 6 x " + std::to_string(n) +
                                         " bodies (or empty for the current state)" :
                                     "a multiple of " + std::to_string(D) + " values (the sum of the " + std::to_string(n) +
                                         " bodies' dofs), or empty for the current state",
                          q.size()));
    configurations = q.size() / D;
    requireFinite(q.data(), q.size(), "q");
  }
  checkMassMatrixBudget(configurations, n, per_m + (derivatives ? per_dm : 0), all_free, derivatives, q.size());

  MassMatrixAnswer answer;
  for (std::size_t index : indices)
  {
    answer.bodies.push_back(scene_.bodies[index].body.name);
    answer.dofs.push_back(static_cast<std::uint32_t>(dofs(index)));
  }
  answer.mass_matrices.resize(configurations * per_m);
  answer.cos_theta.resize(configurations * n);
  if (derivatives)
    answer.derivatives.resize(configurations * per_dm);
  // Body i's x: q + x_offset[i], D apart, or its current state; matrix (k, i)
  // at k per_m + m_offset[i], cos_theta (k n + i).
  for (std::size_t i = 0; i < n; ++i)
  {
    const SceneBody& body = scene_.bodies[indices[i]];
    const double* x = q.empty() ? current[indices[i]].data() : q.data() + x_offset[i];
    double* M = answer.mass_matrices.data() + m_offset[i];
    if (body.articulated)
      detail::articulatedMassMatrices(*body.articulated, x, configurations, D, per_m, n, M, answer.cos_theta.data() + i);
    else
      bodyMassMatrices(body.body, x, configurations, D, per_m, n, M, answer.cos_theta.data() + i);
  }
  if (derivatives)
    for (std::size_t k = 0; k < configurations; ++k)
      for (std::size_t i = 0; i < n; ++i)
      {
        const SceneBody& body = scene_.bodies[indices[i]];
        const double* x = q.empty() ? current[indices[i]].data() : q.data() + k * D + x_offset[i];
        double* out = answer.derivatives.data() + k * per_dm + dm_offset[i];
        if (body.articulated)
        {
          detail::articulatedMassMatrixDerivativesRowMajor(*body.articulated, x, out);
          continue;
        }
        const std::array<Matrix6<double>, 6> dM =
            massMatrixDerivatives(RpyTrig<double>(x[PHI], x[THETA], 0.0), body.body.inertia_body);
        for (int j = 0; j < 6; ++j)
          writeRowMajor6(dM[j], out + 36 * j);
      }
  // Finite inputs can still overflow (e.g. an inertia near DBL_MAX): never
  // return a non-finite number silently.
  requireFinite(answer.mass_matrices.data(), answer.mass_matrices.size(), "result mass_matrices");
  requireFinite(answer.derivatives.data(), answer.derivatives.size(), "result derivatives");
  return answer;
}

void SceneQueries::checkMassMatrixBudget(std::size_t configurations, std::size_t bodies, std::size_t per_configuration,
                                         bool all_free, bool derivatives, std::size_t q_size) const
{
  // For 6-dof bodies per_configuration = 36 n (252 n with derivatives), so
  // this is "configurations x bodies <= kMaxMassMatrices(WithDerivatives)".
  const std::size_t budget =
      derivatives ? RequestLimits::kMaxMassMatrixDoublesWithDerivatives : RequestLimits::kMaxMassMatrixDoubles;
  if (per_configuration == 0 || configurations <= budget / per_configuration)
    return;
  if (all_free)
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
