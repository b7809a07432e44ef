// Every service a core member answers (DRB_CORE_SERVICES, from each .srv's
// declaration), as fuzz_scene_queries.cpp's last request kind: a declared
// service picked by index, each request field fuzzed by its type (names:
// known, unknown, empty, random; float64[]: K x D values of the listed bodies
// (all when none, K = 0 to 3, sometimes one more), after a vertex list also
// K x 3 values per selected vertex, or a random size and any doubles;
// uint32[]: vertex indices; flags; uint8: any value), the member
// called as the node's handler calls it. A service added with a declaration
// is fuzzed without a line here.
//
// Invariant: a request either throws InvalidArgumentError, or answers with
// only finite numbers in every float64[] and float32[] response field (the
// joint limits, joint_lower and joint_upper, may be infinite: "none"; never NaN).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "diff_rigid_body/exceptions.h"
#include "fuzz_dynamics_requests.h"
#include "fuzz_invariants.h"
#include "fuzz_scene_inputs.h"

namespace drb_fuzz
{
/// What a request's fuzzed fields have chosen so far: the bodies that size its arrays, and
/// the vertices a vertex list selects (its length; all of one listed body's when empty).
struct FuzzedRequest
{
  std::vector<std::string> bodies;
  std::size_t K = 1;
  bool lists_vertices = false;
  std::size_t vertices = 0;
};

/// How many vertices `listed` selects on the request's one body (0 for none or an unknown one).
inline std::size_t selectedVertices(const FuzzedRequest& request, const std::vector<std::uint32_t>& listed)
{
  if (!listed.empty())
    return listed.size();
  const int index = request.bodies.size() == 1 ? findBody(queries().scene(), request.bodies[0]) : -1;
  return index < 0 ? 0 : queries().scene().bodies[static_cast<std::size_t>(index)].vertexCount();
}

inline void fuzzField(FuzzedDataProvider& in, FuzzedRequest& request, std::string& body)
{
  body = fuzzedName(in);
  request.bodies = { body };
}
inline void fuzzField(FuzzedDataProvider& in, FuzzedRequest& request, std::vector<std::string>& names)
{
  names = fuzzedNames(in);
  if (request.bodies.empty())  // a body list; a later list (frames) keeps the body's size
    request.bodies = names;
}
/// K configurations of the bodies' coordinates or, after a vertex list, as often of 3
/// values per selected vertex (dL/dp); the input picks.
inline void fuzzField(FuzzedDataProvider& in, FuzzedRequest& request, std::vector<double>& values)
{
  const bool per_vertex = request.lists_vertices && in.ConsumeBool();
  values = fuzzedConfigurations(in, per_vertex ? 3 * request.vertices : coordinatesOf(request.bodies), request.K);
}
inline void fuzzField(FuzzedDataProvider& in, FuzzedRequest& request, std::vector<std::uint32_t>& vertices)
{
  vertices = fuzzedVertices(in);
  request.lists_vertices = true;
  request.vertices = selectedVertices(request, vertices);
}
inline void fuzzField(FuzzedDataProvider& in, FuzzedRequest&, bool& flag)
{
  flag = in.ConsumeBool();
}
inline void fuzzField(FuzzedDataProvider& in, FuzzedRequest&, std::uint8_t& value)
{
  value = in.ConsumeIntegral<std::uint8_t>();
}

/// The response fields whose numbers may be infinite: joint limits, +-inf where a joint has none.
inline bool mayBeInfinite(const char* field)
{
  return std::strcmp(field, "joint_lower") == 0 || std::strcmp(field, "joint_upper") == 0;
}

template <typename T>
void requireFiniteField(const T&, const char*)
{
}
inline void requireFiniteField(const std::vector<double>& values, const char* field)
{
  if (!mayBeInfinite(field))
    return requireAllFinite(values.data(), values.size(), field);
  for (std::size_t i = 0; i < values.size(); ++i)
    if (std::isnan(values[i]))
      violated(std::string(field) + "[" + std::to_string(i) + "] is NaN");
}
inline void requireFiniteField(const std::vector<float>& values, const char* field)
{
  requireAllFinite(values.data(), values.size(), field);
}

#define DRB_FUZZ_FIELD(type, name)                                                                                     \
  type name{};                                                                                                         \
  fuzzField(in, request, name);
#define DRB_FUZZ_ARGUMENT(type, name) , name
#define DRB_FUZZ_FINITE(type, name) requireFiniteField(answer.name, #name);
#define DRB_FUZZ_CORE(Type, service, handler, member, Answer)                                                          \
  if (index-- == 0)                                                                                                    \
  {                                                                                                                    \
    FuzzedRequest request;                                                                                             \
    request.K = in.ConsumeIntegralInRange<std::size_t>(0, 3);                                                          \
    DRB_##Type##_REQUEST_FIELDS(DRB_FUZZ_FIELD) diff_rigid_body::Answer answer;                                        \
    try                                                                                                                \
    {                                                                                                                  \
      queries().member(current DRB_##Type##_REQUEST_FIELDS(DRB_FUZZ_ARGUMENT), answer);                                \
    }                                                                                                                  \
    catch (const diff_rigid_body::InvalidArgumentError&)                                                               \
    {                                                                                                                  \
      return;                                                                                                          \
    }                                                                                                                  \
    DRB_##Type##_RESPONSE_FIELDS(DRB_FUZZ_FINITE) return;                                                              \
  }
#define DRB_FUZZ_COUNT(Type, service, handler, member, Answer) +1

/// How many services DRB_CORE_SERVICES declares.
constexpr int kDeclaredServices = 0 DRB_CORE_SERVICES(DRB_FUZZ_COUNT);
static_assert(kDeclaredServices > 0, "DRB_CORE_SERVICES declares no service to fuzz");

/// One request to a declared service, picked by the input.
inline void declaredServiceRequest(FuzzedDataProvider& in, const diff_rigid_body::SceneState& current)
{
  int index = in.ConsumeIntegralInRange<int>(0, kDeclaredServices - 1);
  DRB_CORE_SERVICES(DRB_FUZZ_CORE)
}

#undef DRB_FUZZ_FIELD
#undef DRB_FUZZ_ARGUMENT
#undef DRB_FUZZ_FINITE
#undef DRB_FUZZ_CORE
#undef DRB_FUZZ_COUNT

}  // namespace drb_fuzz
