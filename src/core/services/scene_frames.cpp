// SceneQueries::frameJacobians and centerOfMass: the requests' checks and
// layout, and frame_jacobians.h per configuration.
#include <algorithm>
#include <memory>
#include <sstream>
#include <unordered_map>

#include "diff_rigid_body/algorithm/frame_jacobians.h"
#include "diff_rigid_body/algorithm/kinematics.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "services/request_checks.h"
#include "services/request_layout.h"
#include "services/thread_scratch.h"

namespace diff_rigid_body
{
using detail::checkDynamicsBudget;
using detail::dynamicsConfigurations;
using detail::reject;
using detail::slice;

namespace
{
/// A listed frame: a link of the body (model.links index), or a static link
/// (scene.static_links index, `fixed`; kFixedFrame for the fixed frame itself).
struct FrameSlot
{
  std::size_t index = 0;
  bool fixed = false;
};
constexpr std::size_t kFixedFrame = static_cast<std::size_t>(-1);

/// "a, b, c" of at most 20 names, then how many there are.
template <typename Names>
std::string listed(const Names& names)
{
  constexpr std::size_t kListed = 20;
  std::string out;
  for (std::size_t i = 0; i < std::min(kListed, names.size()); ++i)
    out += (i ? ", " : "") + names[i].name;
  if (names.size() > kListed)
    out += ", ... (" + std::to_string(names.size()) + ")";
  return out;
}

/// The slots of `frames` (empty = every link of the body `body_index`), or a
/// refusal naming the unknown frame and the body's links; `links` maps a
/// link name to (body, link index).
void frameSlots(const Scene& scene, std::size_t body_index, const std::vector<std::string>& frames,
                const std::unordered_map<std::string, std::pair<std::size_t, std::size_t>>& links,
                std::vector<FrameSlot>& slots)
{
  const BodyModel& body = scene.bodies[body_index];
  slots.clear();
  if (frames.empty())
  {
    for (std::size_t l = 0; l < body.links.size(); ++l)
      slots.push_back({ l, false });
    return;
  }
  if (frames.size() > RequestLimits::kMaxStates)
    reject(detail::sizeMismatch("frames", "at most " + std::to_string(RequestLimits::kMaxStates) + " names",
                                frames.size()));
  for (std::size_t f = 0; f < frames.size(); ++f)
  {
    const auto link = links.find(frames[f]);
    if (link != links.end() && link->second.first == body_index)
    {
      slots.push_back({ link->second.second, false });
      continue;
    }
    if (frames[f] == scene.fixed_frame)
    {
      slots.push_back({ kFixedFrame, true });
      continue;
    }
    const auto fixed = std::find_if(scene.static_links.begin(), scene.static_links.end(),
                                    [&](const StaticLink& s) { return s.name == frames[f]; });
    if (fixed != scene.static_links.end())
    {
      slots.push_back({ static_cast<std::size_t>(fixed - scene.static_links.begin()), true });
      continue;
    }
    const std::string name = frames[f].size() > 64 ? frames[f].substr(0, 64) + "..." : frames[f];
    const std::string elsewhere =
        link == links.end() ? "" : " (it is a link of body '" + scene.bodies[link->second.first].name + "')";
    reject("frames[" + std::to_string(f) + "]: unknown frame '" + name + "': not a link of body '" + body.name +
           "' (its links: " + listed(body.links) + "), a static link" +
           (scene.static_links.empty() ? "" : " (" + listed(scene.static_links) + ")") + " or the fixed frame '" +
           scene.fixed_frame + "'" + elsewhere);
  }
}

/// This thread's resolution of its last frameJacobians request: the body, the listed frames'
/// slots, the segments whose placement they need, and the body's workspace. A request that
/// names the same body and frames on the same scene reuses it (no name lookups); the needed
/// segments are marked again only when the frames or the acceleration bias (which needs every
/// segment) change, the workspace only when the scene or the body does.
class FrameScratch
{
public:
  std::size_t body_index = 0;
  std::vector<FrameSlot> slots;
  std::unique_ptr<BodyWorkspace<double>> workspace;

  /// Unless this thread's previous request on scene `scene_id` named the same body and frames:
  /// body_index = resolve(slots), which fills the slots (and refuses unknown names).
  template <typename Resolve>
  void lookUp(std::uint64_t scene_id, const Scene& scene, const std::string& body_name,
              const std::vector<std::string>& frames, const Resolve& resolve)
  {
    if (scene_id == scene_id_ && body_name == body_name_ && frames == frames_)
      return;
    const bool same_body = scene_id == scene_id_ && body_name == body_name_;
    scene_id_ = 0;  // nothing is resolved until resolve() returns
    marked_ = false;
    body_index = resolve(slots);
    if (!same_body || !workspace)
      workspace = std::make_unique<BodyWorkspace<double>>(scene.bodies[body_index]);
    body_name_ = body_name;
    frames_ = frames;
    scene_id_ = scene_id;
  }

  const std::vector<char>& needed(const BodyModel& body, bool every_segment)
  {
    if (marked_ && every_segment == every_segment_)
      return needed_;
    needed_.assign(body.segments.size(), every_segment ? 1 : 0);
    for (const FrameSlot& slot : slots)
      if (!slot.fixed)
        markSupport(body, slot.index, needed_);
    every_segment_ = every_segment;
    marked_ = true;
    return needed_;
  }

private:
  std::uint64_t scene_id_ = 0;  // SceneQueries ids start at 1
  std::string body_name_;
  std::vector<std::string> frames_;
  std::vector<char> needed_;
  bool marked_ = false, every_segment_ = false;
};

FrameReference frameReference(std::uint32_t reference)
{
  if (reference > 2)
    reject("reference: " + std::to_string(reference) +
           " is not one of 0 (WORLD), 1 (LOCAL), 2 (LOCAL_WORLD_ALIGNED)");
  return static_cast<FrameReference>(reference);
}

/// A static frame's slot: its fixed pose, zero Jacobian and bias.
void writeStaticFrame(const Eigen::Isometry3d& pose, std::size_t d, double* pose12, double* jacobian, double* bias)
{
  const Eigen::Vector3d p = pose.translation();
  const Eigen::Matrix3d R = pose.linear();
  for (int i = 0; i < 3; ++i)
    pose12[i] = p[i];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      pose12[3 + 3 * r + c] = R(r, c);
  std::fill(jacobian, jacobian + 6 * d, 0.0);
  if (bias)
    std::fill(bias, bias + 6, 0.0);
}
}  // namespace

void SceneQueries::frameJacobians(const SceneState& current, const std::string& body_name,
                                  const std::vector<std::string>& frames, DoubleView q,
                                  DoubleView qdot, std::uint32_t reference, bool acceleration_bias,
                                  FrameJacobianAnswer& answer) const
{
  FrameScratch& scratch = detail::threadScratch<FrameScratch>();
  scratch.lookUp(id_, scene_, body_name, frames, [&](std::vector<FrameSlot>& slots) {
    const std::size_t found = bodyIndex(body_name, "body");
    frameSlots(scene_, found, frames, link_index_, slots);
    return found;
  });
  const std::size_t index = scratch.body_index;
  const BodyModel& body = scene_.bodies[index];
  const std::vector<FrameSlot>& slots = scratch.slots;
  const FrameReference ref = frameReference(reference);
  const std::size_t d = body.coordinates, F = slots.size();
  const std::size_t K = dynamicsConfigurations(d, 1, q, { { "qdot", &qdot } });
  checkDynamicsBudget(K, F * (12 + 6 * d + (acceleration_bias ? 6 : 0)) + 1, true);
  answer.frames.resize(F);
  for (std::size_t f = 0; f < F; ++f)
  {
    const std::string& name = !slots[f].fixed                 ? body.links[slots[f].index].name
                              : slots[f].index == kFixedFrame ? scene_.fixed_frame
                                                              : scene_.static_links[slots[f].index].name;
    if (answer.frames[f] != name)  // a reused answer usually holds it already
      answer.frames[f] = name;
  }
  answer.dofs = static_cast<std::uint32_t>(d);
  answer.poses.resize(K * F * 12);
  answer.jacobians.resize(K * F * 6 * d);
  answer.acceleration_bias.resize(acceleration_bias ? K * F * 6 : 0);
  answer.cos_theta.resize(K);
  BodyWorkspace<double>& ws = *scratch.workspace;
  // Without the bias, only the listed frames' paths to the root are placed.
  const std::vector<char>& needed = scratch.needed(body, acceleration_bias);
  for (std::size_t k = 0; k < K; ++k)
  {
    const double* x = q.empty() ? current[index].data() : q.data() + k * d;
    forwardKinematicsOf(body, ws, x, needed);
    if (acceleration_bias)
      frameMotion(body, ws, slice(qdot, k * d));
    for (std::size_t f = 0; f < F; ++f)
    {
      const std::size_t n = k * F + f;
      double* bias = acceleration_bias ? answer.acceleration_bias.data() + 6 * n : nullptr;
      if (slots[f].fixed)
        writeStaticFrame(slots[f].index == kFixedFrame ? Eigen::Isometry3d::Identity()
                                                       : scene_.static_links[slots[f].index].pose_in_fixed_frame,
                         d, answer.poses.data() + 12 * n, answer.jacobians.data() + 6 * d * n, bias);
      else
        frameJacobian(body, ws, slots[f].index, ref, answer.poses.data() + 12 * n,
                      answer.jacobians.data() + 6 * d * n, bias);
    }
    answer.cos_theta[k] = rootCosTheta(body, ws);
  }
  detail::requireFiniteResults({ { "result poses", &answer.poses },
                         { "result jacobians", &answer.jacobians },
                         { "result acceleration_bias", &answer.acceleration_bias } });
}

void SceneQueries::centerOfMass(const SceneState& current, const std::vector<std::string>& bodies,
                                DoubleView q, DoubleView qdot, bool jacobians,
                                CenterOfMassAnswer& answer) const
{
  const detail::BatchedBodies batch = detail::batchedBodies(*this, bodies, q, { { "qdot", &qdot } });
  const std::vector<std::size_t>& indices = batch.indices;
  const detail::RequestLayout& layout = batch.layout;
  const std::size_t K = batch.K, n = indices.size();
  checkDynamicsBudget(K, 4 * n + (jacobians ? 3 * layout.D + 3 * n : 0), jacobians);
  for (std::size_t i = 0; i < n; ++i)
    if (!(scene_.bodies[indices[i]].mass() > 0.0))
      reject("bodies[" + std::to_string(i) + "]: body '" + scene_.bodies[indices[i]].name +
             "' has no mass, so its centre of mass is undefined");
  detail::setBodies(*this, indices, answer);
  answer.masses.resize(n);
  answer.com.resize(K * n * 3);
  answer.jacobians.resize(jacobians ? K * 3 * layout.D : 0);
  answer.acceleration_bias.resize(jacobians ? K * n * 3 : 0);
  detail::forEachBodySlot(*this, layout, indices, K, current, q, answer.cos_theta, [&](const detail::BodySlot& slot) {
    answer.masses[slot.n % n] = diff_rigid_body::centerOfMass(
        scene_.bodies[slot.body], workspace(slot.body), slot.x, slice(qdot, slot.v), answer.com.data() + 3 * slot.n,
        jacobians ? answer.jacobians.data() + 3 * slot.v : nullptr,
        jacobians ? answer.acceleration_bias.data() + 3 * slot.n : nullptr);
  });
  detail::requireFiniteResults({ { "result com", &answer.com },
                         { "result jacobians", &answer.jacobians },
                         { "result acceleration_bias", &answer.acceleration_bias } });
}

}  // namespace diff_rigid_body
