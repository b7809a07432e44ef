// The dynamics requests of fuzz_scene_queries.cpp: inverse_dynamics (with
// and without C and the derivatives) and forward_dynamics (with and without
// derivatives) on fuzzed body lists and arrays of plausible (K x D, K = 1 to
// 3, sometimes one off) or random sizes, any doubles (+-pi/2 among them:
// gimbal lock).
//
// Invariants: a request either throws InvalidArgumentError with a message,
// or answers with the documented sizes and only finite numbers, and each of
// its K configurations' blocks has the bits of a request with that
// configuration alone.
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include "diff_rigid_body/exceptions.h"
#include "fuzz_invariants.h"
#include "fuzz_scene_inputs.h"

namespace drb_fuzz
{
/// Coordinates per configuration of the listed bodies (all when empty), or
/// 0 when one is unknown.
inline std::size_t coordinatesOf(const std::vector<std::string>& names)
{
  std::size_t D = 0;
  if (names.empty())
  {
    for (std::size_t i = 0; i < queries().scene().bodies.size(); ++i)
      D += queries().dofs(i);
    return D;
  }
  for (const std::string& name : names)
  {
    const int index = findBody(queries().scene(), name);
    if (index < 0)
      return 0;
    D += queries().dofs(static_cast<std::size_t>(index));
  }
  return D;
}

/// An array of K x D values (K = 0 to 3, sometimes one more value), or of
/// a random size.
inline std::vector<double> fuzzedConfigurations(FuzzedDataProvider& in, std::size_t D, std::size_t K)
{
  if (D == 0 || in.ConsumeIntegralInRange<int>(0, 5) == 0)
    return fuzzedDoubles(in, 24);
  std::vector<double> values(K * D + (in.ConsumeIntegralInRange<int>(0, 9) == 0 ? 1 : 0));
  for (double& value : values)
    value = fuzzedDouble(in);
  return values;
}

/// values[k * per, (k + 1) * per), or empty when `values` is.
inline std::vector<double> block(const std::vector<double>& values, std::size_t k, std::size_t per)
{
  if (values.empty())
    return {};
  return std::vector<double>(values.begin() + static_cast<long>(k * per),
                             values.begin() + static_cast<long>((k + 1) * per));
}

inline bool sameBits(const std::vector<double>& all, std::size_t k, const std::vector<double>& one)
{
  return all.size() >= (k + 1) * one.size() &&
         (one.empty() || std::memcmp(all.data() + k * one.size(), one.data(), sizeof(double) * one.size()) == 0);
}

inline void inverseDynamicsRequest(FuzzedDataProvider& in, const drb::SceneState& current)
{
  const std::vector<std::string> names = fuzzedNames(in);
  const std::size_t D = coordinatesOf(names), K = in.ConsumeIntegralInRange<std::size_t>(0, 3);
  const std::vector<double> q = fuzzedConfigurations(in, D, K), qdot = fuzzedConfigurations(in, D, K),
                            qddot = fuzzedConfigurations(in, D, K);
  const bool coriolis = in.ConsumeBool(), derivatives = in.ConsumeBool();
  drb::InverseDynamicsAnswer answer;
  try
  {
    queries().inverseDynamics(current, names, q, qdot, qddot, coriolis, derivatives, answer);
  }
  catch (const drb::InvalidArgumentError& refused)
  {
    require(std::string(refused.what()).size() > 0, "inverse_dynamics: a refusal without a message");
    return;
  }
  const std::size_t configurations = q.empty() ? 1 : q.size() / D;
  std::size_t per_m = 0;
  for (std::uint32_t d : answer.dofs)
    per_m += std::size_t(d) * d;
  require(answer.tau.size() == configurations * D && answer.velocity_terms.size() == answer.tau.size() &&
              answer.gravity_terms.size() == answer.tau.size(),
          "inverse_dynamics: wrong vector sizes");
  require(answer.coriolis_matrices.size() == (coriolis ? configurations * per_m : 0) &&
              answer.dtau_dq.size() == (derivatives ? configurations * per_m : 0) &&
              answer.dtau_dqdot.size() == answer.dtau_dq.size(),
          "inverse_dynamics: wrong matrix sizes");
  for (const auto* values : { &answer.tau, &answer.velocity_terms, &answer.gravity_terms, &answer.coriolis_matrices,
                              &answer.dtau_dq, &answer.dtau_dqdot, &answer.cos_theta })
    requireAllFinite(values->data(), values->size(), "inverse_dynamics answer");
  for (std::size_t k = 0; configurations > 1 && k < configurations; ++k)
  {
    drb::InverseDynamicsAnswer one;
    queries().inverseDynamics(current, names, block(q, k, D), block(qdot, k, D), block(qddot, k, D), coriolis,
                              derivatives, one);
    require(sameBits(answer.tau, k, one.tau) && sameBits(answer.dtau_dq, k, one.dtau_dq) &&
                sameBits(answer.coriolis_matrices, k, one.coriolis_matrices),
            "inverse_dynamics: a configuration's block differs from its single request");
  }
}

inline void forwardDynamicsRequest(FuzzedDataProvider& in, const drb::SceneState& current)
{
  const std::vector<std::string> names = fuzzedNames(in);
  const std::size_t D = coordinatesOf(names), K = in.ConsumeIntegralInRange<std::size_t>(0, 3);
  const std::vector<double> q = fuzzedConfigurations(in, D, K), qdot = fuzzedConfigurations(in, D, K),
                            tau = fuzzedConfigurations(in, D, K);
  const bool derivatives = in.ConsumeBool();
  drb::ForwardDynamicsAnswer answer;
  try
  {
    queries().forwardDynamics(current, names, q, qdot, tau, derivatives, answer);
  }
  catch (const drb::InvalidArgumentError& refused)
  {
    require(std::string(refused.what()).size() > 0, "forward_dynamics: a refusal without a message");
    return;
  }
  const std::size_t configurations = q.empty() ? 1 : q.size() / D;
  std::size_t per_m = 0;
  for (std::uint32_t d : answer.dofs)
    per_m += std::size_t(d) * d;
  require(answer.qddot.size() == configurations * D, "forward_dynamics: wrong qddot size");
  require(answer.dqddot_dq.size() == (derivatives ? configurations * per_m : 0) &&
              answer.dqddot_dqdot.size() == answer.dqddot_dq.size() &&
              answer.dqddot_dtau.size() == answer.dqddot_dq.size(),
          "forward_dynamics: wrong matrix sizes");
  for (const auto* values :
       { &answer.qddot, &answer.dqddot_dq, &answer.dqddot_dqdot, &answer.dqddot_dtau, &answer.cos_theta })
    requireAllFinite(values->data(), values->size(), "forward_dynamics answer");
  for (std::size_t k = 0; configurations > 1 && k < configurations; ++k)
  {
    drb::ForwardDynamicsAnswer one;
    queries().forwardDynamics(current, names, block(q, k, D), block(qdot, k, D), block(tau, k, D), derivatives, one);
    require(sameBits(answer.qddot, k, one.qddot) && sameBits(answer.dqddot_dq, k, one.dqddot_dq),
            "forward_dynamics: a configuration's block differs from its single request");
  }
}

}  // namespace drb_fuzz
