// SceneQueries::backprop*: the vertex gradients' request checks and the
// vector-Jacobian product (vertex_backprop.h) per configuration.
#include <algorithm>
#include <cmath>

#include "diff_rigid_body/algorithm/kinematics.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "diff_rigid_body/algorithm/vertex_backprop.h"
#include "services/request_checks.h"

namespace diff_rigid_body
{
using detail::reject;
using detail::sizeMismatch;

void SceneQueries::backpropConfigurations(const SceneState& current, const std::string& body_name,
                                          const std::vector<std::uint32_t>& vertices,
                                          DoubleView gradients, DoubleView q,
                                          std::vector<double>& gradient) const
{
  const std::size_t index = bodyIndex(body_name, "body");
  const std::size_t count = checkVertices(index, vertices);
  const std::size_t d = dofs(index);
  const std::size_t configurations = configurationCount(q, index, count, 0);
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
  const BodyModel& body = scene_.bodies[index];
  BodyWorkspace<double>& ws = workspace(index);
  std::vector<double>& answer = gradient;
  answer.resize(d * configurations);
  for (std::size_t k = 0; k < configurations; ++k)
  {
    if (!vertexBackprop(body, ws, vertices, gradients.data() + 3 * count * k, configurationQ(current, index, q, k),
                        answer.data() + d * k))
    {
      gradient.clear();
      reject((configurations > 1 ? "q (configuration " + std::to_string(k) + ")" : std::string("q")) +
             ": position too large: vertex positions of body '" + body.name + "' would overflow");
    }
  }
  // One pass over the gradients, not two: dL/dx is not finite whenever some
  // g_i is not (inf and NaN never cancel back to a finite value, and
  // 0 x inf is NaN), so only a non-finite answer needs the scan that names
  // the index.
  if (!std::all_of(answer.begin(), answer.end(), [](double value) { return std::isfinite(value); }))
  {
    const std::vector<double> result = std::move(answer);
    gradient.clear();
    requireFinite(gradients.data(), gradients.size(), "gradients");
    requireFinite(result.data(), result.size(), "result gradient (the gradients are too large)");
  }
}

std::vector<double> SceneQueries::backpropConfigurations(const SceneState& current, const std::string& body,
                                                         const std::vector<std::uint32_t>& vertices,
                                                         DoubleView gradients,
                                                         DoubleView q) const
{
  std::vector<double> gradient;
  backpropConfigurations(current, body, vertices, gradients, q, gradient);
  return gradient;
}

Eigen::VectorXd SceneQueries::backprop(const SceneState& current, const std::string& body_name,
                                       const std::vector<std::uint32_t>& vertices,
                                       DoubleView gradients, DoubleView q) const
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
