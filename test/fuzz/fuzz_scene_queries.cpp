// libFuzzer target: the decoding and validation of every service request,
// on SceneQueries over a small fixed scene (fuzz_scene_inputs.h: a free
// object, a fixed-base body and a floating tree; no files are read).
//
// The input is decoded with FuzzedDataProvider into up to 8 requests, each
// one of set_state, get_state, get_mass_matrix, get_vertex_jacobians, its
// compact variant (double and float32), backprop, inverse_dynamics and
// forward_dynamics (fuzz_dynamics_requests.h) (K = 1 to 3 configurations),
// or any service a core member answers (fuzz_declared_services.h),
// with fuzzed body names (known, unknown, empty, repeated, random bytes), q,
// rates, forces and gradients (any double: NaN, +-Inf, subnormals, +-0,
// huge, +-pi/2, or plain values), vertex indices (in range or any uint32)
// and sizes.
// set_state changes the current state that later requests see, so queries
// also run on extreme (finite) states.
//
// Invariants: a request either throws InvalidArgumentError and leaves its
// outputs untouched, or answers with the documented sizes and only finite
// numbers (K blocks for K configurations, each the bits of its single
// request); set_state is all or nothing and stores q bit for bit.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "diff_rigid_body/exceptions.h"
#include "fuzz_declared_services.h"
#include "fuzz_dynamics_requests.h"
#include "fuzz_invariants.h"
#include "fuzz_scene_inputs.h"

namespace
{
namespace drb = diff_rigid_body;
using drb_fuzz::fuzzedDouble;
using drb_fuzz::fuzzedDoubles;
using drb_fuzz::fuzzedName;
using drb_fuzz::fuzzedNames;
using drb_fuzz::fuzzedVertices;
using drb_fuzz::queries;
using drb_fuzz::require;
using drb_fuzz::requireAllFinite;

void setState(FuzzedDataProvider& in, drb::SceneState& current)
{
  std::vector<drb::NamedState> updates(in.ConsumeIntegralInRange<std::size_t>(0, 4));
  for (drb::NamedState& update : updates)
  {
    update.name = fuzzedName(in);
    const int index = drb_fuzz::findBody(queries().scene(), update.name);
    update.x.resize(index >= 0 ? static_cast<Eigen::Index>(queries().dofs(static_cast<std::size_t>(index))) : 6);
    for (Eigen::Index k = 0; k < update.x.size(); ++k)
      update.x[k] = fuzzedDouble(in);
  }
  drb::SceneState next;
  try
  {
    next = queries().applyStates(current, updates);
  }
  catch (const drb::InvalidArgumentError&)
  {
    return;  // all or nothing: `current` is untouched (it is const in the call)
  }
  require(next.size() == current.size(), "set_state: state size changed");
  std::vector<bool> updated(current.size(), false);
  for (const drb::NamedState& update : updates)
  {
    const int index = drb_fuzz::findBody(queries().scene(), update.name);
    require(index >= 0, "set_state accepted an unknown body");
    require(!updated[index], "set_state accepted a repeated body");
    updated[index] = true;
    require(next[index].size() == update.x.size() &&
                std::memcmp(next[index].data(), update.x.data(), sizeof(double) * update.x.size()) == 0,
            "set_state did not store q bit for bit");
  }
  for (std::size_t i = 0; i < next.size(); ++i)
  {
    require(static_cast<std::size_t>(next[i].size()) == queries().dofs(i), "state: wrong length");
    requireAllFinite(next[i].data(), next[i].size(), "state");
    if (!updated[i])
      require(std::memcmp(next[i].data(), current[i].data(), sizeof(double) * next[i].size()) == 0,
              "set_state changed a body it was not given");
  }
  current = next;
}

void getState(FuzzedDataProvider& in, const drb::SceneState& current)
{
  const std::vector<std::string> names = fuzzedNames(in);
  try
  {
    const std::vector<drb::NamedState> states = queries().getStates(current, names);
    require(states.size() == (names.empty() ? current.size() : names.size()), "get_state: wrong count");
    for (std::size_t i = 0; i < names.size(); ++i)
      require(states[i].name == names[i], "get_state: wrong name");
  }
  catch (const drb::InvalidArgumentError&)
  {
  }
}

void getMassMatrix(FuzzedDataProvider& in, const drb::SceneState& current)
{
  const std::vector<std::string> names = fuzzedNames(in);
  const bool derivatives = in.ConsumeBool();
  std::vector<double> q;
  if (in.ConsumeBool())
  {
    // A plausible size: K x 6 x n values, sometimes off by one.
    const std::size_t n = names.empty() ? current.size() : names.size();
    q.resize(in.ConsumeIntegralInRange<std::size_t>(0, 3) * 6 * n + (in.ConsumeBool() ? 1 : 0));
    for (double& value : q)
      value = fuzzedDouble(in);
  }
  else
    q = fuzzedDoubles(in, 48);
  try
  {
    const drb::MassMatrixAnswer answer = queries().massMatrices(current, names, q, derivatives);
    const std::size_t n = names.empty() ? current.size() : names.size();
    std::size_t D = 0, per_m = 0, per_dm = 0;
    for (std::uint32_t d : answer.dofs)
    {
      D += d;
      per_m += d * d;
      per_dm += d * d * d;
    }
    const std::size_t K = q.empty() ? 1 : q.size() / D;
    require(answer.bodies.size() == n && answer.dofs.size() == n, "get_mass_matrix: wrong body count");
    require(answer.mass_matrices.size() == per_m * K, "get_mass_matrix: wrong matrix count");
    require(answer.cos_theta.size() == n * K, "get_mass_matrix: wrong cos_theta count");
    require(answer.derivatives.size() == (derivatives ? per_dm * K : 0), "get_mass_matrix: wrong derivatives");
    requireAllFinite(answer.mass_matrices.data(), answer.mass_matrices.size(), "mass_matrices");
    requireAllFinite(answer.derivatives.data(), answer.derivatives.size(), "derivatives");
    requireAllFinite(answer.cos_theta.data(), answer.cos_theta.size(), "cos_theta");
  }
  catch (const drb::InvalidArgumentError&)
  {
  }
}

std::vector<double> fuzzedQ(FuzzedDataProvider& in)
{
  if (in.ConsumeBool())
    return {};
  if (in.ConsumeBool())
  {
    // K = 1 to 3 whole configurations.
    std::vector<double> q(6 * in.ConsumeIntegralInRange<std::size_t>(1, 3));
    for (double& value : q)
      value = fuzzedDouble(in);
    return q;
  }
  return fuzzedDoubles(in, 20);
}

/// K of an accepted request's q for body `index`: 1 when empty (the current state), else its size / dofs.
std::size_t configurationsOf(const std::vector<double>& q, int index)
{
  return q.empty() ? 1 : q.size() / queries().dofs(static_cast<std::size_t>(index));
}

std::size_t vertexCountOf(int index)
{
  return queries().scene().bodies[static_cast<std::size_t>(index)].vertexCount();
}

void getVertexJacobians(FuzzedDataProvider& in, const drb::SceneState& current)
{
  const std::string body = fuzzedName(in);
  const std::vector<std::uint32_t> vertices = fuzzedVertices(in);
  const std::vector<double> q = fuzzedQ(in);
  std::vector<double> positions{ 42.0 }, jacobians{ 43.0 };
  try
  {
    queries().vertexJacobians(current, body, vertices, q, positions, jacobians);
  }
  catch (const drb::InvalidArgumentError&)
  {
    require(positions == std::vector<double>{ 42.0 } && jacobians == std::vector<double>{ 43.0 },
            "get_vertex_jacobians: a refused request wrote its outputs");
    return;
  }
  const int index = drb_fuzz::findBody(queries().scene(), body);
  require(index >= 0, "get_vertex_jacobians accepted an unknown body");
  const std::size_t count =
      vertices.empty() ? vertexCountOf(index) : vertices.size();
  const std::size_t K = configurationsOf(q, index);
  const std::size_t d = queries().dofs(static_cast<std::size_t>(index));
  require(positions.size() == 3 * count * K && jacobians.size() == 3 * d * count * K,
          "get_vertex_jacobians: wrong sizes");
  requireAllFinite(positions.data(), positions.size(), "positions");
  requireAllFinite(jacobians.data(), jacobians.size(), "jacobians");
  // Configuration k's block has the bits of a request with its d values alone.
  for (std::size_t k = 0; K > 1 && k < K; ++k)
  {
    std::vector<double> p1, j1;
    queries().vertexJacobians(current, body, vertices, std::vector<double>(q.begin() + d * k, q.begin() + d * k + d),
                              p1, j1);
    require(std::memcmp(p1.data(), positions.data() + 3 * count * k, sizeof(double) * p1.size()) == 0 &&
                std::memcmp(j1.data(), jacobians.data() + 3 * d * count * k, sizeof(double) * j1.size()) == 0,
            "get_vertex_jacobians: a configuration's block differs from its single request");
  }
}

/// ~get_vertex_jacobians_compact: positions and the rotation block, in
/// double or float32, or positions only.
template <typename Out>
void vertexRotationJacobians(FuzzedDataProvider& in, const drb::SceneState& current)
{
  const std::string body = fuzzedName(in);
  const std::vector<std::uint32_t> vertices = fuzzedVertices(in);
  const std::vector<double> q = fuzzedQ(in);
  const bool positions_only = in.ConsumeBool();
  std::vector<Out> positions{ Out(42) }, rotation_jacobians{ Out(43) };
  try
  {
    queries().vertexRotationJacobians<Out>(current, body, vertices, q, positions_only, positions,
                                           rotation_jacobians);
  }
  catch (const drb::InvalidArgumentError&)
  {
    require(positions == std::vector<Out>{ Out(42) } && rotation_jacobians == std::vector<Out>{ Out(43) },
            "get_vertex_jacobians_compact: a refused request wrote its outputs");
    return;
  }
  const int index = drb_fuzz::findBody(queries().scene(), body);
  require(index >= 0, "get_vertex_jacobians_compact accepted an unknown body");
  const std::size_t count =
      vertices.empty() ? vertexCountOf(index) : vertices.size();
  const std::size_t K = configurationsOf(q, index);
  const std::size_t w = queries().compactColumns(static_cast<std::size_t>(index));
  require(positions.size() == 3 * count * K && rotation_jacobians.size() == (positions_only ? 0 : 3 * w * count * K),
          "get_vertex_jacobians_compact: wrong sizes");
  for (const std::vector<Out>* values : { &positions, &rotation_jacobians })
    for (std::size_t i = 0; i < values->size(); ++i)
      require(std::isfinite((*values)[i]), "get_vertex_jacobians_compact: an answer is not finite");
}

void backprop(FuzzedDataProvider& in, const drb::SceneState& current)
{
  const std::string body = fuzzedName(in);
  const std::vector<std::uint32_t> vertices = fuzzedVertices(in);
  const std::vector<double> q = fuzzedQ(in);
  std::vector<double> gradients;
  const int index = drb_fuzz::findBody(queries().scene(), body);
  if (index >= 0 && in.ConsumeBool())
  {
    // The expected size, so that the values are what is tested.
    const std::size_t count =
        vertices.empty() ? vertexCountOf(index) : vertices.size();
    const std::size_t d = queries().dofs(static_cast<std::size_t>(index));
    const std::size_t K = q.size() >= d ? q.size() / d : 1;
    gradients.resize(3 * count * K + (in.ConsumeIntegralInRange<int>(0, 7) == 0 ? 1 : 0));
    for (double& value : gradients)
      value = fuzzedDouble(in);
  }
  else
    gradients = fuzzedDoubles(in, 48);
  try
  {
    const std::vector<double> gradient = queries().backpropConfigurations(current, body, vertices, gradients, q);
    const int index = drb_fuzz::findBody(queries().scene(), body);
    require(gradient.size() == queries().dofs(static_cast<std::size_t>(index)) * configurationsOf(q, index),
            "backprop: wrong size");
    requireAllFinite(gradient.data(), gradient.size(), "backprop gradient");
  }
  catch (const drb::InvalidArgumentError&)
  {
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  FuzzedDataProvider in(data, size);
  drb::SceneState current = queries().initialState();
  for (int request = 0; request < 8 && in.remaining_bytes() > 0; ++request)
  {
    switch (in.ConsumeIntegralInRange<int>(0, 9))
    {
      case 0:
        setState(in, current);
        break;
      case 1:
        getState(in, current);
        break;
      case 2:
        getMassMatrix(in, current);
        break;
      case 3:
        getVertexJacobians(in, current);
        break;
      case 4:
        vertexRotationJacobians<double>(in, current);
        break;
      case 5:
        vertexRotationJacobians<float>(in, current);
        break;
      case 6:
        backprop(in, current);
        break;
      case 7:
        drb_fuzz::inverseDynamicsRequest(in, current);
        break;
      case 8:
        drb_fuzz::forwardDynamicsRequest(in, current);
        break;
      default:
        drb_fuzz::declaredServiceRequest(in, current);
        break;
    }
  }
  return 0;
}
