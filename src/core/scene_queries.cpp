#include "diff_rigid_body/scene_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <unordered_set>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass_matrix.h"
#include "scene_queries_articulated.h"

namespace diff_rigid_body
{
namespace
{
[[noreturn]] void reject(const std::string& message)
{
  throw InvalidArgumentError(message);
}

std::string sizeMismatch(const std::string& field, const std::string& expected, std::size_t got)
{
  std::ostringstream why;
  why << field << ": expected " << expected << ", got " << got << " values";
  return why.str();
}

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
// "q: ... would overflow<suffix>", naming configuration k when there are several.
std::string overflowMessage(const std::string& body, std::size_t configurations, std::size_t k, const char* suffix)
{
  return (configurations > 1 ? "q (configuration " + std::to_string(k) + ")" : std::string("q")) +
         ": position too large: vertex positions of body '" + body + "' would overflow" + suffix;
}

// At most 64 bytes of a name for a message: a hostile name may be huge.
std::string shortened(const std::string& name)
{
  return name.size() > 64 ? name.substr(0, 64) + "..." : name;
}
}  // namespace

void requireFinite(const double* values, std::size_t count, const std::string& field)
{
  for (std::size_t i = 0; i < count; ++i)
  {
    if (!std::isfinite(values[i]))
    {
      std::ostringstream why;
      why << field << "[" << i << "]: not finite (" << values[i] << ")";
      reject(why.str());
    }
  }
}

SceneQueries::SceneQueries(Scene scene) : scene_(std::move(scene))
{
  for (const SceneBody& body : scene_.bodies)
  {
    vertex_radius_.push_back(body.body.vertices.cols() ? body.body.vertices.colwise().norm().maxCoeff() : 0.0);
    vertex_columns_.emplace_back(body.body.vertices.transpose());
  }
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
    body_index_.emplace(scene_.bodies[i].body.name, i);  // the first of equal names
  // Independent joints first, so that a mimic joint never shadows one.
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
    if (const ArticulatedBody* body = scene_.bodies[i].articulated.get())
      for (std::size_t k = 0; k < body->joint_names.size(); ++k)
        joint_index_.emplace(body->joint_names[k], std::make_pair(i, body->rootCoordinates() + k));
  for (const SceneBody& scene_body : scene_.bodies)
    if (scene_body.articulated)
      for (const Segment& segment : scene_body.articulated->segments)
        if (!segment.joint.empty() && joint_index_.count(segment.joint) == 0)
          mimic_joints_.insert(segment.joint);
}

SceneState SceneQueries::initialState() const
{
  SceneState state;
  state.reserve(scene_.bodies.size());
  for (const SceneBody& body : scene_.bodies)
    state.push_back(body.initial_state);
  return state;
}

std::size_t SceneQueries::bodyIndex(const std::string& name, const std::string& field) const
{
  const auto found = body_index_.find(name);
  if (found != body_index_.end())
    return found->second;
  // At most 20 names, so that a large scene does not make every refusal huge.
  constexpr std::size_t kListed = 20;
  std::string known;
  for (std::size_t i = 0; i < std::min(kListed, scene_.bodies.size()); ++i)
    known += (known.empty() ? "" : ", ") + scene_.bodies[i].body.name;
  if (scene_.bodies.size() > kListed)
    known += ", ... (" + std::to_string(scene_.bodies.size()) + " bodies)";
  reject(field + ": unknown body '" + shortened(name) + "' (bodies: " + known + ")");
}

std::vector<std::size_t> SceneQueries::bodyIndices(const std::vector<std::string>& names,
                                                   const std::string& field) const
{
  if (names.size() > RequestLimits::kMaxStates)
    reject(sizeMismatch(field, "at most " + std::to_string(RequestLimits::kMaxStates) + " names", names.size()));
  std::vector<std::size_t> indices;
  if (names.empty())
  {
    for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
      indices.push_back(i);
    return indices;
  }
  indices.reserve(names.size());
  for (std::size_t i = 0; i < names.size(); ++i)
    indices.push_back(bodyIndex(names[i], field + "[" + std::to_string(i) + "]"));
  return indices;
}

SceneState SceneQueries::applyStates(const SceneState& current, const std::vector<NamedState>& updates) const
{
  if (updates.size() > RequestLimits::kMaxStates)
    reject(sizeMismatch("states", "at most " + std::to_string(RequestLimits::kMaxStates) + " states",
                        updates.size()));
  std::unordered_set<std::size_t> seen;
  std::vector<std::size_t> indices;
  indices.reserve(updates.size());
  for (std::size_t i = 0; i < updates.size(); ++i)
  {
    const std::string field = "states[" + std::to_string(i) + "]";
    const std::size_t index = bodyIndex(updates[i].name, field + ".name");
    if (!seen.insert(index).second)
      reject(field + ".name: body '" + updates[i].name + "' appears more than once");
    const std::string q_field = field + ".q (body '" + updates[i].name + "')";
    const std::size_t dofs = scene_.bodies[index].dofs();
    if (static_cast<std::size_t>(updates[i].q.size()) != dofs)
      reject(sizeMismatch(q_field, std::to_string(dofs) + " values (the body's dofs)",
                          static_cast<std::size_t>(updates[i].q.size())));
    requireFinite(updates[i].q.data(), dofs, q_field);
    indices.push_back(index);
  }
  SceneState next = current;
  for (std::size_t i = 0; i < updates.size(); ++i)
    next[indices[i]] = updates[i].q;
  return next;
}

SceneState SceneQueries::applyJointPositions(const SceneState& current, const std::vector<std::string>& names,
                                             const std::vector<double>& positions,
                                             std::vector<std::string>& unknown_names) const
{
  if (names.size() > RequestLimits::kMaxStates)
    reject(sizeMismatch("name", "at most " + std::to_string(RequestLimits::kMaxStates) + " names", names.size()));
  if (positions.size() != names.size())
    reject(sizeMismatch("position", std::to_string(names.size()) + " values (one per name)", positions.size()));
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (!std::isfinite(positions[i]))
    {
      std::ostringstream why;
      why << "position[" << i << "] (joint '" << shortened(names[i]) << "'): not finite (" << positions[i] << ")";
      reject(why.str());
    }
  SceneState next = current;
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    const auto found = joint_index_.find(names[i]);
    if (found != joint_index_.end())
      next[found->second.first][static_cast<Eigen::Index>(found->second.second)] = positions[i];
    else if (mimic_joints_.count(names[i]) == 0)
      unknown_names.push_back(names[i]);
  }
  return next;
}

std::vector<NamedState> SceneQueries::getStates(const SceneState& current, const std::vector<std::string>& names) const
{
  std::vector<NamedState> states;
  for (std::size_t index : bodyIndices(names, "bodies"))
    states.push_back({ scene_.bodies[index].body.name, current[index] });
  return states;
}

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

std::size_t SceneQueries::checkVertices(std::size_t index, const std::vector<std::uint32_t>& vertices) const
{
  const SceneBody& body = scene_.bodies[index];
  const std::size_t available = body.vertexCount();
  const std::size_t count = vertices.empty() ? available : vertices.size();
  if (count > RequestLimits::kMaxVertices)
    reject(sizeMismatch("vertices", "at most " + std::to_string(RequestLimits::kMaxVertices) + " vertices", count));
  for (std::size_t i = 0; i < vertices.size(); ++i)
  {
    if (vertices[i] >= available)
    {
      std::ostringstream why;
      why << "vertices[" << i << "]: index " << vertices[i] << " out of range for body '" << body.body.name
          << "' with " << available << " vertices";
      reject(why.str());
    }
  }
  return count;
}

std::size_t SceneQueries::configurationCount(const std::vector<double>& q, std::size_t dofs,
                                             std::size_t vertex_count) const
{
  if (q.empty())
    return 1;
  const std::string d = std::to_string(dofs);
  if (q.size() % dofs != 0)
    reject(sizeMismatch("q",
                        d + " values per configuration (" + d +
                            " K for K configurations, or empty for the current state)",
                        q.size()));
  const std::size_t configurations = q.size() / dofs;
  const std::size_t limit = RequestLimits::kMaxVertices;
  // Both factors are at most 2^22 when multiplied, so the product cannot wrap.
  if (configurations > limit || configurations * vertex_count > limit)
  {
    std::ostringstream why;
    why << "q, vertices: expected at most " << limit << " vertices over all configurations (configurations x "
        << "vertices), got " << configurations << " x " << vertex_count;
    reject(why.str());
  }
  return configurations;
}

void SceneQueries::checkPositionsFit(const SceneState& current, std::size_t index, const std::vector<double>& q,
                                     std::size_t configurations, double inflation, double limit,
                                     const char* suffix) const
{
  // B = |t|_inf + inflation r, r = max_i |p0_i|, bounds every output of a
  // configuration (see vertexRotationJacobians for the inflation).
  for (std::size_t k = 0; k < configurations; ++k)
  {
    const double* qk = configurationQ(current, index, q, k);
    const double t = std::max({ std::abs(qk[TX]), std::abs(qk[TY]), std::abs(qk[TZ]) });
    if (!(t + inflation * vertex_radius_[index] <= limit))
      reject(overflowMessage(scene_.bodies[index].body.name, configurations, k, suffix));
  }
}

const double* SceneQueries::configurationQ(const SceneState& current, std::size_t index, const std::vector<double>& q,
                                           std::size_t k) const
{
  return q.empty() ? current[index].data() : q.data() + dofs(index) * k;
}

ArticulatedPose<double> SceneQueries::checkedPose(const SceneState& current, std::size_t index,
                                                  const std::vector<double>& q, std::size_t configurations,
                                                  std::size_t k) const
{
  const ArticulatedBody& body = *scene_.bodies[index].articulated;
  ArticulatedPose<double> pose = articulatedPose(body, configurationQ(current, index, q, k));
  if (!detail::poseIsFinite(body, pose))
    reject(overflowMessage(scene_.bodies[index].body.name, configurations, k, ""));
  return pose;
}

std::size_t SceneQueries::compactColumns(std::size_t index) const
{
  const ArticulatedBody* body = scene_.bodies[index].articulated.get();
  if (!body)
    return 3;
  return body->floating_root ? body->dofs() - 3 : body->dofs();
}

void SceneQueries::vertexJacobians(const SceneState& current, const std::string& body_name,
                                   const std::vector<std::uint32_t>& vertices, const std::vector<double>& q,
                                   std::vector<double>& positions, std::vector<double>& jacobians) const
{
  const std::size_t index = bodyIndex(body_name, "body");
  const std::size_t count = checkVertices(index, vertices);
  const std::size_t configurations = configurationCount(q, dofs(index), count);
  requireFinite(q.data(), q.size(), "q");
  if (scene_.bodies[index].articulated)
  {
    articulatedCompact<double>(current, index, vertices, count, q, configurations, false, {}, positions, jacobians);
    return;
  }
  // |p| <= |t|_inf + max_i |p0_i| bounds every output, so one check per
  // configuration up front rules out overflow for all vertices.
  checkPositionsFit(current, index, q, configurations, 1.0, std::numeric_limits<double>::max(), "");
  positions.resize(3 * count * configurations);
  jacobians.resize(18 * count * configurations);
  for (std::size_t k = 0; k < configurations; ++k)
  {
    const BodyPose<double> pose(Eigen::Map<const Vector6<double>>(configurationQ(current, index, q, k)));
    vertexPositionsAndJacobians(pose, scene_.bodies[index].body.vertices, vertices, positions.data() + 3 * count * k,
                                jacobians.data() + 18 * count * k);
  }
}

template <typename Out>
void SceneQueries::articulatedCompact(const SceneState& current, std::size_t index,
                                      const std::vector<std::uint32_t>& vertices, std::size_t count,
                                      const std::vector<double>& q, std::size_t configurations, bool positions_only,
                                      const std::vector<int>& columns, std::vector<Out>& positions,
                                      std::vector<Out>& jacobians) const
{
  // Computed in double into new buffers, checked against max(Out), then
  // swapped in: a refused request leaves the outputs untouched.
  const ArticulatedBody& body = *scene_.bodies[index].articulated;
  const std::size_t width = columns.empty() ? body.dofs() : columns.size();
  std::vector<double> P(3 * count * configurations), J(positions_only ? 0 : 3 * width * count * configurations);
  for (std::size_t k = 0; k < configurations; ++k)
    articulatedVertexJacobians(body, checkedPose(current, index, q, configurations, k), vertices, columns,
                               P.data() + 3 * count * k, positions_only ? nullptr : J.data() + 3 * width * count * k);
  const char* suffix = std::is_same<Out, float>::value ? " float32" : "";
  const std::size_t bad_p = detail::firstValueBeyond<Out>(P), bad_j = detail::firstValueBeyond<Out>(J);
  if (bad_p < P.size())
    reject(overflowMessage(scene_.bodies[index].body.name, configurations, bad_p / (3 * count), suffix));
  if (bad_j < J.size())
    reject(overflowMessage(scene_.bodies[index].body.name, configurations, bad_j / (3 * width * count), suffix));
  if constexpr (std::is_same<Out, double>::value)
  {
    positions.swap(P);
    jacobians.swap(J);
  }
  else
  {
    positions.assign(P.begin(), P.end());
    jacobians.assign(J.begin(), J.end());
  }
}

template <typename Out>
void SceneQueries::vertexRotationJacobians(const SceneState& current, const std::string& body_name,
                                           const std::vector<std::uint32_t>& vertices, const std::vector<double>& q,
                                           bool positions_only, std::vector<Out>& positions,
                                           std::vector<Out>& rotation_jacobians) const
{
  const std::size_t index = bodyIndex(body_name, "body");
  const std::size_t count = checkVertices(index, vertices);
  const std::size_t configurations = configurationCount(q, dofs(index), count);
  if (const ArticulatedBody* body = scene_.bodies[index].articulated.get())
  {
    requireFinite(q.data(), q.size(), "q");
    articulatedCompact<Out>(current, index, vertices, count, q, configurations, positions_only,
                            detail::compactColumnList(*body), positions, rotation_jacobians);
    return;
  }
  // B = |t|_inf + r, r = max_i |p0_i|, bounds every output: |p_k| <= |t_k| + |R p0|,
  // and column j of Jr is T e_j x R p0 with |T e_j| = 1, so |Jr_kj| <= |p0|.
  // Rounding (in R p0, the cross products and the norm behind r) adds less than
  // 20 eps r, so with r inflated by 64 eps, B rounded to nearest <= max(Out)
  // rules out inf in every output, with one check per configuration. Up to
  // that term (below an ulp of B unless r > 1e306 m) this is the test of
  // vertexJacobians: B finite in double.
  constexpr double kInflation = 1.0 + 64 * std::numeric_limits<double>::epsilon();
  constexpr double kLimit = std::numeric_limits<Out>::max();
  requireFinite(q.data(), q.size(), "q");
  checkPositionsFit(current, index, q, configurations, kInflation, kLimit,
                    std::is_same<Out, float>::value ? " float32" : "");
  positions.resize(3 * count * configurations);
  rotation_jacobians.resize(positions_only ? 0 : 9 * count * configurations);
  for (std::size_t k = 0; k < configurations; ++k)
  {
    const BodyPose<double> pose(Eigen::Map<const Vector6<double>>(configurationQ(current, index, q, k)));
    vertexPositionsAndRotationJacobians(pose, scene_.bodies[index].body.vertices, vertices,
                                        positions.data() + 3 * count * k,
                                        positions_only ? nullptr : rotation_jacobians.data() + 9 * count * k);
  }
}
template void SceneQueries::vertexRotationJacobians<double>(const SceneState&, const std::string&,
                                                            const std::vector<std::uint32_t>&,
                                                            const std::vector<double>&, bool, std::vector<double>&,
                                                            std::vector<double>&) const;
template void SceneQueries::vertexRotationJacobians<float>(const SceneState&, const std::string&,
                                                           const std::vector<std::uint32_t>&,
                                                           const std::vector<double>&, bool, std::vector<float>&,
                                                           std::vector<float>&) const;

std::vector<double> SceneQueries::backpropConfigurations(const SceneState& current, const std::string& body_name,
                                                         const std::vector<std::uint32_t>& vertices,
                                                         const std::vector<double>& gradients,
                                                         const std::vector<double>& q) const
{
  const std::size_t index = bodyIndex(body_name, "body");
  const std::size_t count = checkVertices(index, vertices);
  const std::size_t d = dofs(index);
  const std::size_t configurations = configurationCount(q, d, count);
  if (gradients.size() != 3 * count * configurations)
  {
    if (configurations == 1)
      reject(sizeMismatch("gradients", "3 per vertex = " + std::to_string(3 * count), gradients.size()));
    reject(sizeMismatch("gradients",
                        "3 per vertex and configuration = 3 x " + std::to_string(count) + " vertices x " +
                            std::to_string(configurations) + " configurations = " +
                            std::to_string(3 * count * configurations),
                        gradients.size()));
  }
  requireFinite(q.data(), q.size(), "q");
  std::vector<double> gradient(d * configurations);
  const ArticulatedBody* articulated = scene_.bodies[index].articulated.get();
  for (std::size_t k = 0; k < configurations; ++k)
  {
    const double* g = gradients.data() + 3 * count * k;
    if (articulated)
    {
      articulatedBackprop(*articulated, checkedPose(current, index, q, configurations, k), vertices, g,
                          gradient.data() + d * k);
      continue;
    }
    const BodyPose<double> pose(Eigen::Map<const Vector6<double>>(configurationQ(current, index, q, k)));
    // All vertices or an index list: the by-coordinate engine (vertex_columns.h).
    const Vector6<double> dL_dq = backpropagateVertexGradients(pose, vertex_columns_[index], vertices, g);
    std::copy(dL_dq.data(), dL_dq.data() + 6, gradient.data() + 6 * k);
  }
  // One pass over the gradients, not two: dL/dt = sum_i g_i (a free body or
  // floating root; for a fixed base, the root joint's v . sum_i g_i + ...) is
  // not finite whenever some g_i is not (inf and NaN never cancel back to a
  // finite value, and 0 x inf is NaN), so only a non-finite answer needs the
  // scan that names the index.
  if (!std::all_of(gradient.begin(), gradient.end(), [](double value) { return std::isfinite(value); }))
  {
    requireFinite(gradients.data(), gradients.size(), "gradients");
    requireFinite(gradient.data(), gradient.size(), "result gradient (the gradients are too large)");
  }
  return gradient;
}

Eigen::VectorXd SceneQueries::backprop(const SceneState& current, const std::string& body_name,
                                       const std::vector<std::uint32_t>& vertices,
                                       const std::vector<double>& gradients, const std::vector<double>& q) const
{
  // One configuration only: backpropConfigurations takes several. (The body
  // is looked up there; an unknown one is checked against 6 values here.)
  const auto found = body_index_.find(body_name);
  const std::size_t d = found == body_index_.end() ? 6 : dofs(found->second);
  if (!q.empty() && q.size() != d)
    reject(sizeMismatch("q", std::to_string(d) + " values (or empty for the current state)", q.size()));
  const std::vector<double> gradient = backpropConfigurations(current, body_name, vertices, gradients, q);
  return Eigen::Map<const Eigen::VectorXd>(gradient.data(), static_cast<Eigen::Index>(gradient.size()));
}

}  // namespace diff_rigid_body
