// How diff_rigid_body_ros::RigidBodyPool (rigid_body_pool.h) cuts a K-configuration request into
// contiguous shards and joins the answers, apart from the calls.
//
// Every sharded field travels configuration-major (configuration k's values are one contiguous run
// of the same length for every k), so a shard of configurations [start, stop) is a slice of each
// per-configuration request field, and the whole answer is the concatenation of the shards'
// per-configuration response fields in shard order. The node computes each configuration alone, so
// the joined answer has the bits of one instance's answer.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "diff_rigid_body/services/service_tables.h"  // generated from srv/*.srv
#include "diff_rigid_body_ros/services.h"

namespace diff_rigid_body_ros
{
namespace pool
{
/// Per sharded service: its name, the request fields that hold K runs (an empty field, e.g. qdot =
/// zeros, stays empty in every shard) and the response fields that do, as member pointers: the
/// fields whose comment in the .srv begins with "[per configuration]" (DRB_SHARDED_SERVICES).
template <typename Service>
struct Sharding;

#define DRB_POOL_SHARDING(Type, request_fields, response_fields)                                                      \
  template <>                                                                                                          \
  struct Sharding<diff_rigid_body::Type>                                                                               \
  {                                                                                                                    \
    using Request = diff_rigid_body::Type::Request;                                                                    \
    using Response = diff_rigid_body::Type::Response;                                                                  \
    static constexpr const char* service = ServiceName<diff_rigid_body::Type>::value;                                  \
    static auto requestFields() { return std::make_tuple request_fields; }                                            \
    static auto responseFields() { return std::make_tuple response_fields; }                                          \
  };
DRB_SHARDED_SERVICES(DRB_POOL_SHARDING)
#undef DRB_POOL_SHARDING

/// True for a service the pool can shard (one with a Sharding<Service>): the K-configuration ones.
template <typename Service, typename = void>
struct IsSharded : std::false_type
{
};
template <typename Service>
struct IsSharded<Service, std::void_t<decltype(Sharding<Service>::service)>> : std::true_type
{
};

/// The scene's d per body name, and its body order (an empty `bodies` field means all of them).
struct SceneDofs
{
  std::map<std::string, std::uint32_t> by_name;
  std::vector<std::string> order;
};

namespace detail
{
// The bodies a request's q covers: its `bodies` list (empty = all), or its one `body`.
template <typename Request>
auto requestBodies(const Request& r, const SceneDofs& scene, int) -> decltype(r.bodies, std::vector<std::string>())
{
  return r.bodies.empty() ? scene.order : std::vector<std::string>(r.bodies.begin(), r.bodies.end());
}
template <typename Request>
std::vector<std::string> requestBodies(const Request& r, const SceneDofs&, long)
{
  return { r.body };
}
}  // namespace detail

/// K, the configurations of a request the pool may shard, or 0: q empty (the node's current
/// state), an unknown body, or sizes that do not fit K (the node's own refusal is then the answer).
template <typename Service>
std::size_t configurationCount(const typename Service::Request& request, const SceneDofs& scene)
{
  std::size_t width = 0;
  for (const std::string& body : detail::requestBodies(request, scene, 0))
  {
    const auto found = scene.by_name.find(body);
    if (found == scene.by_name.end())
      return 0;
    width += found->second;
  }
  if (request.q.empty() || width == 0 || request.q.size() % width)
    return 0;
  const std::size_t K = request.q.size() / width;
  bool fits = true;
  std::apply([&](auto... field) { ((fits = fits && (request.*field).size() % K == 0), ...); },
             Sharding<Service>::requestFields());
  return fits ? K : 0;
}

/// K configurations cut into weights.size() contiguous counts proportional to `weights` (e.g.
/// measured configurations per second): the largest-remainder rounding, so the counts sum to K.
/// When K >= weights.size(), every instance gets at least one configuration, taken from the
/// largest count: an instance measured slow once (a cold start) is measured again, not starved.
inline std::vector<std::size_t> apportion(std::size_t K, std::vector<double> weights)
{
  double total = 0.0;
  for (double& w : weights)
    total += (w = std::isfinite(w) && w > 0.0 ? w : 0.0);
  if (!(total > 0.0))
    std::fill(weights.begin(), weights.end(), 1.0), total = static_cast<double>(weights.size());
  std::vector<std::size_t> counts(weights.size());
  std::vector<std::pair<double, std::size_t>> remainders;
  std::size_t given = 0;
  for (std::size_t i = 0; i < weights.size(); ++i)
  {
    const double exact = static_cast<double>(K) * weights[i] / total;
    counts[i] = static_cast<std::size_t>(std::floor(exact));
    given += counts[i];
    remainders.emplace_back(-(exact - std::floor(exact)), i);
  }
  std::stable_sort(remainders.begin(), remainders.end());
  for (std::size_t r = 0; given < K && r < remainders.size(); ++r, ++given)
    ++counts[remainders[r].second];
  if (K >= counts.size())
    for (std::size_t& count : counts)
      if (count == 0)
        --*std::max_element(counts.begin(), counts.end()), count = 1;
  return counts;
}

/// Configurations [start, stop) of a request of K: each sharded field's runs, the other fields
/// copied (the sharded fields of `whole` are moved out while it is copied, so no big array is
/// copied whole; `whole` is unchanged on return).
template <typename Service>
typename Service::Request shardRequest(typename Service::Request& whole, std::size_t K, std::size_t start,
                                       std::size_t stop)
{
  const auto fields = Sharding<Service>::requestFields();
  std::vector<std::vector<double>> held;
  std::apply([&](auto... field) { (held.push_back(std::move(whole.*field)), ...); }, fields);
  typename Service::Request part = whole;  // the other fields only: the sharded ones are held
  std::size_t i = 0;
  auto restoreAndSlice = [&](auto field) {
    std::vector<double>& values = whole.*field;
    values = std::move(held[i++]);
    const std::size_t run = values.size() / K;  // values per configuration (0: an empty field)
    (part.*field).assign(values.begin() + run * start, values.begin() + run * stop);
  };
  std::apply([&](auto... field) { (restoreAndSlice(field), ...); }, fields);
  return part;
}

/// Appends a shard's per-configuration response fields to `into` (the answer so far).
template <typename Service>
void appendResponse(typename Service::Response& into, const typename Service::Response& part)
{
  auto append = [&](auto field) {
    (into.*field).insert((into.*field).end(), (part.*field).begin(), (part.*field).end());
  };
  std::apply([&](auto... field) { (append(field), ...); }, Sharding<Service>::responseFields());
}

namespace detail
{
template <typename Vector>
bool sameBits(const Vector& a, const Vector& b)
{
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
}
inline bool sameBits(const std::vector<std::string>& a, const std::vector<std::string>& b) { return a == b; }
}  // namespace detail

/// The first field of two get_bodies answers that would change a pool's answers (bodies, dofs,
/// masses, inertias, joints, vertex counts; bit for bit), or "" when they agree. fixed_frame may
/// differ: each instance has its own frame prefix.
inline std::string sceneMismatch(const diff_rigid_body::GetBodies::Response& a,
                                 const diff_rigid_body::GetBodies::Response& b)
{
  using R = diff_rigid_body::GetBodies::Response;
  const auto fields = std::make_tuple(std::make_pair("names", &R::names), std::make_pair("dofs", &R::dofs),
                                      std::make_pair("masses", &R::masses), std::make_pair("inertias", &R::inertias),
                                      std::make_pair("vertex_counts", &R::vertex_counts),
                                      std::make_pair("joint_names", &R::joint_names),
                                      std::make_pair("joint_counts", &R::joint_counts),
                                      std::make_pair("link_names", &R::link_names),
                                      std::make_pair("link_vertex_counts", &R::link_vertex_counts),
                                      std::make_pair("link_masses", &R::link_masses));
  std::string first;
  auto check = [&](const auto& field) {
    if (first.empty() && !detail::sameBits(a.*(field.second), b.*(field.second)))
      first = field.first;
  };
  std::apply([&](const auto&... field) { (check(field), ...); }, fields);
  return first;
}

}  // namespace pool
}  // namespace diff_rigid_body_ros
