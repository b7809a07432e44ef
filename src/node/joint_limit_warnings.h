// Joint positions outside the URDF's <limit>: rigid_body_server accepts them (limits are not
// enforced, as robot_state_publisher does not enforce them) and warns, once per joint, naming the
// body, the joint, the value and the limits.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "diff_rigid_body/services/scene_queries.h"

namespace diff_rigid_body
{
class JointLimitWarnings
{
public:
  explicit JointLimitWarnings(const Scene& scene);

  /// The warnings for the joints of `next` outside [lower, upper] that were not warned about
  /// before (each joint once for the node's life; bodies whose x equals `previous`' are skipped).
  /// A joint whose URDF range is empty (lower >= upper, e.g. limits left 0 0) has no limits here.
  std::vector<std::string> check(const SceneState& previous, const SceneState& next);

private:
  const Scene& scene_;
  std::vector<std::vector<bool>> warned_;  ///< per body, per joint
};
}  // namespace diff_rigid_body
