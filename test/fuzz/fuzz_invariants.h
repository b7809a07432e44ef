// Shared checks of the libFuzzer targets: a violated invariant aborts with a
// message, which libFuzzer reports as a crash and saves the input for.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "diff_rigid_body/services/scene_queries.h"

namespace drb_fuzz
{
namespace drb = diff_rigid_body;

[[noreturn]] inline void violated(const std::string& what)
{
  std::fprintf(stderr, "INVARIANT VIOLATED: %s\n", what.c_str());
  std::abort();
}

inline void require(bool condition, const std::string& what)
{
  if (!condition)
    violated(what);
}

template <typename Real>
void requireAllFinite(const Real* values, std::size_t count, const std::string& what)
{
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      violated(what + "[" + std::to_string(i) + "] is not finite");
}

/// Index of the first body called `name` in `scene`, or -1 (a reference
/// lookup, independent of SceneQueries' hash map).
inline int findBody(const drb::Scene& scene, const std::string& name)
{
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (scene.bodies[i].name == name)
      return static_cast<int>(i);
  return -1;
}

/// Every loaded scene: at least one body; finite mass >= 0, finite
/// symmetric inertia, finite COM, vertices and initial state; finite static
/// link poses.
inline void requireValidScene(const drb::Scene& scene)
{
  require(!scene.bodies.empty(), "a loaded scene has no body");
  for (const drb::BodyModel& body : scene.bodies)
  {
    const std::string where = "body '" + body.name + "': ";
    // Massless bodies load (with a warning); a massive one has a normal mass.
    const double mass = body.mass();
    require(std::isfinite(mass) && mass >= 0.0, where + "mass not finite and >= 0");
    require(mass == 0.0 || std::isnormal(mass), where + "subnormal mass");
    require(body.segments.front().inertia.inertia.allFinite(), where + "inertia not finite");
    require(body.rootComOffset().allFinite(), where + "COM offset not finite");
    require(body.vertices.allFinite(), where + "vertices not finite");
    require(body.initial_x.allFinite(), where + "initial state not finite");
    for (const drb::LinkInBody& link : body.links)
      require(link.pose_in_segment_link.matrix().allFinite(), where + "link pose not finite");
    require(findBody(scene, body.name) >= 0, where + "not found by name");
  }
  for (const drb::StaticLink& link : scene.static_links)
    require(link.pose_in_fixed_frame.matrix().allFinite(), "static link '" + link.name + "': pose not finite");
}

}  // namespace drb_fuzz
