#include "diff_rigid_body/services/scene_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>
#include <unordered_set>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/algorithm/kinematics.h"
#include "services/request_checks.h"

namespace diff_rigid_body
{
using detail::reject;
using detail::sizeMismatch;

namespace
{
/// Refuses an x whose link poses overflow (a prismatic joint at 1e308,
/// say): tf would otherwise publish inf.
void requireFinitePoses(const BodyModel& body, BodyWorkspace<double>& ws, const Eigen::VectorXd& x,
                        const std::string& field)
{
  forwardKinematics(body, ws, x.data());
  if (!kinematicsAreFinite(body, ws))
    reject(field + ": the link poses of body '" + body.name + "' overflow at these values");
}

// At most 64 bytes of a name for a message: a hostile name may be huge.
std::string shortened(const std::string& name)
{
  return name.size() > 64 ? name.substr(0, 64) + "..." : name;
}
}  // namespace

SceneState SceneQueries::initialState() const
{
  SceneState state;
  state.reserve(scene_.bodies.size());
  for (const BodyModel& body : scene_.bodies)
    state.push_back(body.initial_x);
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
    known += (known.empty() ? "" : ", ") + scene_.bodies[i].name;
  if (scene_.bodies.size() > kListed)
    known += ", ... (" + std::to_string(scene_.bodies.size()) + " bodies)";
  reject(field + ": unknown body '" + shortened(name) + "' (bodies: " + known + ")");
}

void SceneQueries::bodyIndices(const std::vector<std::string>& names, const char* field,
                               std::vector<std::size_t>& indices) const
{
  if (names.size() > RequestLimits::kMaxStates)
    reject(sizeMismatch(field, "at most " + std::to_string(RequestLimits::kMaxStates) + " names", names.size()));
  indices.clear();
  if (names.empty())
  {
    for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
      indices.push_back(i);
    return;
  }
  indices.reserve(names.size());
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    const auto found = body_index_.find(names[i]);  // the message is built only for a refusal
    indices.push_back(found != body_index_.end() ? found->second :
                                                   bodyIndex(names[i], std::string(field) + "[" + std::to_string(i) + "]"));
  }
}

std::vector<std::size_t> SceneQueries::bodyIndices(const std::vector<std::string>& names, const char* field) const
{
  std::vector<std::size_t> indices;
  bodyIndices(names, field, indices);
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
    const std::size_t dofs = this->dofs(index);
    if (static_cast<std::size_t>(updates[i].x.size()) != dofs)
      reject(sizeMismatch(q_field, std::to_string(dofs) + " values (the body's dofs)",
                          static_cast<std::size_t>(updates[i].x.size())));
    requireFinite(updates[i].x.data(), dofs, q_field.c_str());
    requireFinitePoses(scene_.bodies[index], workspace(index), updates[i].x, q_field);
    indices.push_back(index);
  }
  SceneState next = current;
  for (std::size_t i = 0; i < updates.size(); ++i)
    next[indices[i]] = updates[i].x;
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
  std::vector<std::size_t> changed;
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    const auto found = joint_index_.find(names[i]);
    if (found != joint_index_.end())
    {
      next[found->second.first][static_cast<Eigen::Index>(found->second.second)] = positions[i];
      changed.push_back(found->second.first);
    }
    else if (mimic_joints_.count(names[i]) == 0)
      unknown_names.push_back(names[i]);
  }
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  for (std::size_t index : changed)
    requireFinitePoses(scene_.bodies[index], workspace(index), next[index], "position");
  return next;
}

std::vector<NamedState> SceneQueries::getStates(const SceneState& current, const std::vector<std::string>& names) const
{
  std::vector<NamedState> states;
  for (std::size_t index : bodyIndices(names, "bodies"))
    states.push_back({ scene_.bodies[index].name, current[index] });
  return states;
}
}  // namespace diff_rigid_body
