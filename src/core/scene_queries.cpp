#include "diff_rigid_body/scene_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <unordered_set>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass_matrix.h"
#include "request_checks.h"
#include "scene_queries_articulated.h"

namespace diff_rigid_body
{
using detail::reject;
using detail::sizeMismatch;

namespace
{
// "q: ... would overflow<suffix>", naming configuration k when there are several.
std::string overflowMessage(const std::string& body, std::size_t configurations, std::size_t k, const char* suffix)
{
  return (configurations > 1 ? "q (configuration " + std::to_string(k) + ")" : std::string("q")) +
         ": position too large: vertex positions of body '" + body + "' would overflow" + suffix;
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

std::size_t SceneQueries::configurationCount(const std::vector<double>& q, std::size_t index,
                                             std::size_t vertex_count) const
{
  const std::size_t dofs = this->dofs(index);
  checkArticulatedWork(index, q.empty() ? 1 : q.size() / dofs, vertex_count);
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

void SceneQueries::checkArticulatedWork(std::size_t index, std::size_t configurations,
                                        std::size_t vertex_count) const
{
  const ArticulatedBody* body = scene_.bodies[index].articulated.get();
  if (!body || configurations > RequestLimits::kMaxVertices || vertex_count > RequestLimits::kMaxVertices)
    return;  // free bodies: version 1's limits; the vertex limit refuses the rest
  // Products of values below 2^22 and of dof x segments (each far below 2^32): no wrap.
  const double answer = 3.0 * double(configurations) * double(vertex_count) * double(1 + body->dofs());
  const double motions = 6.0 * double(body->segments.size()) * double(body->dofs());
  const double budget = double(RequestLimits::kMaxArticulatedDoubles);
  if (answer > budget || motions > budget)
  {
    std::ostringstream why;
    why << "q, vertices: body '" << scene_.bodies[index].body.name << "' (" << body->dofs() << " coordinates, "
        << body->segments.size() << " segments) would need " << std::max(answer, motions)
        << " doubles for this request, more than the limit of " << RequestLimits::kMaxArticulatedDoubles;
    reject(why.str());
  }
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
  const std::size_t configurations = configurationCount(q, index, count);
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
  const std::size_t configurations = configurationCount(q, index, count);
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
  const std::size_t configurations = configurationCount(q, index, count);
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
