#include "diff_rigid_body/scene_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <unordered_set>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass_matrix.h"

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
void writeRowMajor(const Matrix6<double>& M, double* out)
{
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> target(out);
  target = M;
}

// M(q_k) and cos(theta_k) of one body for the states q_k = q + k stride,
// k < count, by massMatrixBatch (mass_matrix.h: vectorised sinCos over
// blocks of states, M written entry by entry). Matrix k goes to slot
// k * slot_stride (36 doubles per slot, one cos_theta per slot): adjacent
// slots are written in place; otherwise (several bodies per configuration)
// blocks of states go through an L1 buffer and are copied to their slots.
void bodyMassMatrices(const RigidBody& body, const double* q, std::size_t count, std::size_t stride,
                      std::size_t slot_stride, double* mass_matrices, double* cos_theta)
{
  if (slot_stride == 1 || count == 1)
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
      const std::size_t slot = (k0 + j) * slot_stride;
      std::copy(block + 36 * j, block + 36 * (j + 1), mass_matrices + 36 * slot);
      cos_theta[slot] = cos_block[j];
    }
  }
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
  const std::string shown = name.size() > 64 ? name.substr(0, 64) + "..." : name;  // a hostile name may be huge
  reject(field + ": unknown body '" + shown + "' (bodies: " + known + ")");
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
    requireFinite(updates[i].q.data(), 6, field + ".q (body '" + updates[i].name + "')");
    indices.push_back(index);
  }
  SceneState next = current;
  for (std::size_t i = 0; i < updates.size(); ++i)
    next[indices[i]] = updates[i].q;
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
  std::size_t configurations = 1;
  if (!q.empty())
  {
    if (n == 0 || q.size() % (6 * n) != 0)
      reject(sizeMismatch("q", "a multiple of 6 x " + std::to_string(n) + " bodies (or empty for the current state)",
                          q.size()));
    configurations = q.size() / (6 * n);
    requireFinite(q.data(), q.size(), "q");
  }
  const std::size_t matrices = configurations * n;
  const std::size_t limit =
      derivatives ? RequestLimits::kMaxMassMatricesWithDerivatives : RequestLimits::kMaxMassMatrices;
  if (matrices > limit)
    reject(sizeMismatch("q", "at most " + std::to_string(limit) + " matrices (configurations x bodies), i.e. " +
                                 std::to_string(limit * 6) + " values",
                        q.size()));

  MassMatrixAnswer answer;
  for (std::size_t index : indices)
    answer.bodies.push_back(scene_.bodies[index].body.name);
  answer.mass_matrices.resize(36 * matrices);
  answer.cos_theta.resize(matrices);
  if (derivatives)
    answer.derivatives.resize(216 * matrices);
  // Body i's states: q + 6 i, 6 n apart (slot k n + i), or its current state.
  for (std::size_t i = 0; i < n; ++i)
    bodyMassMatrices(scene_.bodies[indices[i]].body, q.empty() ? current[indices[i]].data() : q.data() + 6 * i,
                     configurations, 6 * n, n, answer.mass_matrices.data() + 36 * i, answer.cos_theta.data() + i);
  if (derivatives)
  {
    for (std::size_t slot = 0; slot < matrices; ++slot)
    {
      const std::size_t i = slot % n;
      const double* qs = q.empty() ? current[indices[i]].data() : q.data() + 6 * slot;
      const RpyTrig<double> trig(qs[PHI], qs[THETA], 0.0);
      const std::array<Matrix6<double>, 6> dM =
          massMatrixDerivatives(trig, scene_.bodies[indices[i]].body.inertia_body);
      for (int j = 0; j < 6; ++j)
        writeRowMajor(dM[j], answer.derivatives.data() + 216 * slot + 36 * j);
    }
  }
  // Finite inputs can still overflow (e.g. an inertia near DBL_MAX): never
  // return a non-finite number silently.
  requireFinite(answer.mass_matrices.data(), answer.mass_matrices.size(), "result mass_matrices");
  requireFinite(answer.derivatives.data(), answer.derivatives.size(), "result derivatives");
  return answer;
}

std::size_t SceneQueries::checkVertices(std::size_t index, const std::vector<std::uint32_t>& vertices) const
{
  const RigidBody& body = scene_.bodies[index].body;
  const std::size_t available = static_cast<std::size_t>(body.vertices.cols());
  const std::size_t count = vertices.empty() ? available : vertices.size();
  if (count > RequestLimits::kMaxVertices)
    reject(sizeMismatch("vertices", "at most " + std::to_string(RequestLimits::kMaxVertices) + " vertices", count));
  for (std::size_t i = 0; i < vertices.size(); ++i)
  {
    if (vertices[i] >= available)
    {
      std::ostringstream why;
      why << "vertices[" << i << "]: index " << vertices[i] << " out of range for body '" << body.name << "' with "
          << available << " vertices";
      reject(why.str());
    }
  }
  return count;
}

std::size_t SceneQueries::configurationCount(const std::vector<double>& q, std::size_t vertex_count) const
{
  if (q.empty())
    return 1;
  if (q.size() % 6 != 0)
    reject(sizeMismatch("q", "6 values per configuration (6 K for K configurations, or empty for the current state)",
                        q.size()));
  const std::size_t configurations = q.size() / 6;
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
      reject((configurations > 1 ? "q (configuration " + std::to_string(k) + ")" : std::string("q")) +
             ": position too large: vertex positions of body '" + scene_.bodies[index].body.name +
             "' would overflow" + suffix);
  }
}

const double* SceneQueries::configurationQ(const SceneState& current, std::size_t index, const std::vector<double>& q,
                                           std::size_t k) const
{
  return q.empty() ? current[index].data() : q.data() + 6 * k;
}

void SceneQueries::vertexJacobians(const SceneState& current, const std::string& body_name,
                                   const std::vector<std::uint32_t>& vertices, const std::vector<double>& q,
                                   std::vector<double>& positions, std::vector<double>& jacobians) const
{
  const std::size_t index = bodyIndex(body_name, "body");
  const std::size_t count = checkVertices(index, vertices);
  const std::size_t configurations = configurationCount(q, count);
  requireFinite(q.data(), q.size(), "q");
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
void SceneQueries::vertexRotationJacobians(const SceneState& current, const std::string& body_name,
                                           const std::vector<std::uint32_t>& vertices, const std::vector<double>& q,
                                           bool positions_only, std::vector<Out>& positions,
                                           std::vector<Out>& rotation_jacobians) const
{
  const std::size_t index = bodyIndex(body_name, "body");
  const std::size_t count = checkVertices(index, vertices);
  const std::size_t configurations = configurationCount(q, count);
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
  const std::size_t configurations = configurationCount(q, count);
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
  std::vector<double> gradient(6 * configurations);
  for (std::size_t k = 0; k < configurations; ++k)
  {
    const BodyPose<double> pose(Eigen::Map<const Vector6<double>>(configurationQ(current, index, q, k)));
    // All vertices or an index list: the by-coordinate engine (vertex_columns.h).
    const Vector6<double> dL_dq =
        backpropagateVertexGradients(pose, vertex_columns_[index], vertices, gradients.data() + 3 * count * k);
    std::copy(dL_dq.data(), dL_dq.data() + 6, gradient.data() + 6 * k);
  }
  // One pass over the gradients, not two: dL/dt = sum_i g_i is not finite
  // whenever some g_i is not (inf and NaN never cancel back to a finite
  // value), so only a non-finite answer needs the scan that names the index.
  if (!std::all_of(gradient.begin(), gradient.end(), [](double value) { return std::isfinite(value); }))
  {
    requireFinite(gradients.data(), gradients.size(), "gradients");
    requireFinite(gradient.data(), gradient.size(), "result gradient (the gradients are too large)");
  }
  return gradient;
}

Vector6<double> SceneQueries::backprop(const SceneState& current, const std::string& body_name,
                                       const std::vector<std::uint32_t>& vertices,
                                       const std::vector<double>& gradients, const std::vector<double>& q) const
{
  if (!q.empty() && q.size() != 6)  // one configuration only: backpropConfigurations takes several
    reject(sizeMismatch("q", "6 values (or empty for the current state)", q.size()));
  const std::vector<double> gradient = backpropConfigurations(current, body_name, vertices, gradients, q);
  return Eigen::Map<const Vector6<double>>(gradient.data());
}

}  // namespace diff_rigid_body
