#include "joint_limit_warnings.h"

#include <sstream>

namespace diff_rigid_body
{
JointLimitWarnings::JointLimitWarnings(const Scene& scene) : scene_(scene)
{
  for (const BodyModel& body : scene.bodies)
    warned_.emplace_back(body.joint_names.size(), false);
}

std::vector<std::string> JointLimitWarnings::check(const SceneState& previous, const SceneState& next)
{
  std::vector<std::string> warnings;
  for (std::size_t i = 0; i < next.size(); ++i)
  {
    if (i < previous.size() && previous[i].size() == next[i].size() && previous[i] == next[i])
      continue;
    const BodyModel& body = scene_.bodies[i];
    for (std::size_t k = 0; k < body.joint_names.size(); ++k)
    {
      const double lower = body.joint_lower[k], upper = body.joint_upper[k];
      const double value = next[i][static_cast<Eigen::Index>(body.rootCoordinates() + k)];
      if (warned_[i][k] || !(lower < upper) || (value >= lower && value <= upper))
        continue;
      warned_[i][k] = true;
      std::ostringstream text;
      text << "joint '" << body.joint_names[k] << "' of body '" << body.name << "' at " << value
           << " is outside its URDF limits [" << lower << ", " << upper
           << "]; accepted (limits are not enforced; logged once per joint)";
      warnings.push_back(text.str());
    }
  }
  return warnings;
}
}  // namespace diff_rigid_body
