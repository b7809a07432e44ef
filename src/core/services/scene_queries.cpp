#include "diff_rigid_body/services/scene_queries.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/algorithm/kinematics.h"
#include "diff_rigid_body/algorithm/vertex_backprop.h"
#include "services/request_checks.h"
#include "services/thread_scratch.h"

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

std::uint64_t nextQueriesId()
{
  static std::atomic<std::uint64_t> next{ 1 };
  return next++;
}

/// One cache per thread, holding the workspaces of the last SceneQueries it
/// served: a node's spinner threads each keep theirs for good.
struct WorkspaceCache
{
  std::uint64_t owner = 0;
  std::vector<std::unique_ptr<BodyWorkspace<double>>> bodies;
};
}  // namespace

SceneQueries::SceneQueries(Scene scene, const Eigen::Vector3d& gravity)
  : scene_(std::move(scene)), gravity_(gravity), id_(nextQueriesId())
{
  for (const BodyModel& body : scene_.bodies)
  {
    all_columns_.push_back(JacobianColumns::all(body));
    compact_columns_.push_back(JacobianColumns::compact(body));
  }
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
    body_index_.emplace(scene_.bodies[i].name, i);  // the first of equal names
  // Independent joints first, so that a mimic joint never shadows one.
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
  {
    const BodyModel& body = scene_.bodies[i];
    for (std::size_t k = 0; k < body.joint_names.size(); ++k)
      joint_index_.emplace(body.joint_names[k], std::make_pair(i, body.rootCoordinates() + k));
  }
  for (const BodyModel& body : scene_.bodies)
    for (const Segment& segment : body.segments)
      if (segment.joint_type != JointType::Free && joint_index_.count(segment.joint) == 0)
        mimic_joints_.insert(segment.joint);
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
    for (std::size_t l = 0; l < scene_.bodies[i].links.size(); ++l)
      link_index_.emplace(scene_.bodies[i].links[l].name, std::make_pair(i, l));
}

BodyWorkspace<double>& SceneQueries::workspace(std::size_t index) const
{
  WorkspaceCache& cache = detail::threadScratch<WorkspaceCache>();
  if (cache.owner != id_)
  {
    cache.owner = id_;
    cache.bodies.clear();
    cache.bodies.resize(scene_.bodies.size());
  }
  std::unique_ptr<BodyWorkspace<double>>& workspace = cache.bodies[index];
  if (!workspace)
    workspace = std::make_unique<BodyWorkspace<double>>(scene_.bodies[index]);
  return *workspace;
}

void SceneQueries::linkPoses(std::size_t index, const Eigen::VectorXd& x, std::vector<Eigen::Isometry3d>& poses) const
{
  diff_rigid_body::linkPoses(scene_.bodies[index], workspace(index), x.data(), poses);
}

std::size_t SceneQueries::checkVertices(std::size_t index, const std::vector<std::uint32_t>& vertices) const
{
  const BodyModel& body = scene_.bodies[index];
  const std::size_t available = body.vertexCount();
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

std::size_t SceneQueries::configurationCount(DoubleView q, std::size_t index,
                                             std::size_t vertex_count, std::size_t width) const
{
  const std::size_t dofs = this->dofs(index);
  const std::string d = std::to_string(dofs);
  if (q.size() % dofs != 0)
    reject(sizeMismatch("q",
                        d + " values per configuration (" + d +
                            " K for K configurations, or empty for the current state)",
                        q.size()));
  const std::size_t configurations = q.empty() ? 1 : q.size() / dofs;
  const std::size_t limit = RequestLimits::kMaxVertices;
  // Both factors are at most 2^22 when multiplied, so the product cannot wrap.
  if (configurations > limit || configurations * vertex_count > limit)
  {
    std::ostringstream why;
    why << "q, vertices: expected at most " << limit << " vertices over all configurations (configurations x "
        << "vertices), got " << configurations << " x " << vertex_count;
    reject(why.str());
  }
  // K N <= 2^22 and width <= d, far below 2^32: no wrap.
  const std::size_t answer = 3 * configurations * vertex_count * (1 + width);
  if (answer > RequestLimits::kMaxVertexAnswerDoubles)
  {
    std::ostringstream why;
    why << "q, vertices: body '" << scene_.bodies[index].name << "' (" << dofs << " coordinates) would answer "
        << answer << " doubles for this request (3 (1 + " << width
        << ") per vertex and configuration), more than the limit of " << RequestLimits::kMaxVertexAnswerDoubles;
    reject(why.str());
  }
  return configurations;
}

const double* SceneQueries::configurationQ(const SceneState& current, std::size_t index, DoubleView q,
                                           std::size_t k) const
{
  return q.empty() ? current[index].data() : q.data() + dofs(index) * k;
}

void SceneQueries::checkOutputsFit(const SceneState& current, std::size_t index, const JacobianColumns& columns,
                                   const std::vector<std::uint32_t>& vertices, DoubleView q,
                                   std::size_t configurations, double limit, const char* suffix) const
{
  BodyWorkspace<double>& ws = workspace(index);
  for (std::size_t k = 0; k < configurations; ++k)
    if (!(vertexOutputBound(scene_.bodies[index], ws, columns, vertices, configurationQ(current, index, q, k)) <=
          limit))
      reject(overflowMessage(scene_.bodies[index].name, configurations, k, suffix));
}

template <typename Out>
void SceneQueries::vertexQuery(const SceneState& current, const std::string& body_name,
                               const std::vector<std::uint32_t>& vertices, DoubleView q, bool compact,
                               bool positions_only, std::vector<Out>& positions, std::vector<Out>& jacobians) const
{
  const std::size_t index = bodyIndex(body_name, "body");
  const std::size_t count = checkVertices(index, vertices);
  const JacobianColumns& columns = compact ? compact_columns_[index] : all_columns_[index];
  const std::size_t width = positions_only ? 0 : columns.width;
  const std::size_t configurations = configurationCount(q, index, count, width);
  requireFinite(q.data(), q.size(), "q");
  checkOutputsFit(current, index, columns, vertices, q, configurations, std::numeric_limits<Out>::max(),
                  std::is_same<Out, float>::value ? " float32" : "");
  positions.resize(3 * count * configurations);
  jacobians.resize(3 * width * count * configurations);
  const BodyModel& body = scene_.bodies[index];
  BodyWorkspace<double>& ws = workspace(index);
  for (std::size_t k = 0; k < configurations; ++k)
    diff_rigid_body::vertexJacobians(body, ws, columns, vertices, configurationQ(current, index, q, k), positions.data() + 3 * count * k,
                    positions_only ? nullptr : jacobians.data() + 3 * width * count * k);
}

void SceneQueries::vertexJacobians(const SceneState& current, const std::string& body_name,
                                   const std::vector<std::uint32_t>& vertices, DoubleView q,
                                   std::vector<double>& positions, std::vector<double>& jacobians) const
{
  vertexQuery<double>(current, body_name, vertices, q, /*compact=*/false, /*positions_only=*/false, positions,
                      jacobians);
}

template <typename Out>
void SceneQueries::vertexRotationJacobians(const SceneState& current, const std::string& body_name,
                                           const std::vector<std::uint32_t>& vertices, DoubleView q,
                                           bool positions_only, std::vector<Out>& positions,
                                           std::vector<Out>& rotation_jacobians) const
{
  vertexQuery<Out>(current, body_name, vertices, q, /*compact=*/true, positions_only, positions, rotation_jacobians);
}
template void SceneQueries::vertexRotationJacobians<double>(const SceneState&, const std::string&,
                                                            const std::vector<std::uint32_t>&,
                                                            DoubleView, bool, std::vector<double>&,
                                                            std::vector<double>&) const;
template void SceneQueries::vertexRotationJacobians<float>(const SceneState&, const std::string&,
                                                           const std::vector<std::uint32_t>&,
                                                           DoubleView, bool, std::vector<float>&,
                                                           std::vector<float>&) const;

void SceneQueries::vertexJacobiansCompact(const SceneState& current, const std::string& body,
                                          const std::vector<std::uint32_t>& vertices, DoubleView q,
                                          bool positions_only, bool single_precision,
                                          VertexJacobiansCompactAnswer& answer) const
{
  if (single_precision)
    vertexRotationJacobians(current, body, vertices, q, positions_only, answer.positions_f32,
                            answer.rotation_jacobians_f32);
  else
    vertexRotationJacobians(current, body, vertices, q, positions_only, answer.positions,
                            answer.rotation_jacobians);
}

}  // namespace diff_rigid_body
