// The earlier argument orders of RigidBodyClient and RigidBodyPool, kept deprecated so that code
// written against them still compiles (with a warning) and gets the same answers. Every batched
// call now takes the body or bodies first, then q and the other per-configuration values, then
// the selection and the options:
//
//   earlier (deprecated)                           now
//   inverseDynamics(q, qdot, qddot, bodies, ...)   inverseDynamics(bodies, q, qdot, qddot, ...)
//   forwardDynamics(q, qdot, tau, bodies, ...)     forwardDynamics(bodies, q, qdot, tau, ...)
//   frameJacobians(body, q, frames, reference,     frameJacobians(body, q, qdot, frames, reference,
//                  qdot, acceleration_bias)                       acceleration_bias)
//
// The earlier overloads deduce the type of their first moved argument, so that a braced list
// there ({} for all bodies) never selects them: `inverseDynamics({}, q)` is the current order.
// Braced frame names in the earlier place, `frameJacobians(body, q, {"a", "b"})`, select the
// earlier order: a braced list converts to std::initializer_list<Name> before anything else
// (and two names would otherwise be an iterator pair for qdot's vector). Its Name is deduced, so
// `{}` and braced numbers there stay qdot; names of mixed types take the array overload.
// Braced names followed by frames, `frameJacobians(body, q, {"a", "b"}, {"c"})`, fit neither order
// and do not compile (a deleted overload), where the names would be qdot's iterator pair.
// A CRTP base of EigenBatches (client_batches.h).
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <type_traits>
#include <vector>

#include "diff_rigid_body_ros/client_arrays.h"
#include "diff_rigid_body_ros/client_frames.h"
#include "diff_rigid_body_ros/client_types.h"

namespace diff_rigid_body_ros
{
namespace detail
{
/// `IfFlat<Values> = 0`: Values is std::vector<double> (K configurations concatenated).
template <typename Values>
using IfFlat = std::enable_if_t<std::is_same<Values, std::vector<double>>::value, int>;
/// `IfEigenBatch<Values> = 0`: Values is a std::vector of Eigen vectors (one per configuration).
template <typename Values>
using IfEigenBatch = IfEigenVector<typename Values::value_type>;
/// A parameter whose type is taken from another one (never deduced from its own argument).
template <typename T>
using Same = typename std::common_type<T>::type;
}  // namespace detail

template <typename Derived>
class EarlierOrders
{
public:
  template <typename Values, detail::IfFlat<Values> = 0>
  [[deprecated("inverseDynamics(bodies, q, qdot, qddot, ...): the bodies come first now")]] InverseDynamicsResult
  inverseDynamics(const Values& q, const Values& qdot = {}, const Values& qddot = {},
                  const std::vector<std::string>& bodies = {}, bool coriolis_matrices = false,
                  bool derivatives = false)
  {
    return derived().inverseDynamics(bodies, q, qdot, qddot, coriolis_matrices, derivatives);
  }
  template <typename Values, detail::IfEigenBatch<Values> = 0>
  [[deprecated("inverseDynamics(bodies, qs, qdots, qddots, ...): the bodies come first now")]] InverseDynamicsResult
  inverseDynamics(const Values& qs, const detail::Same<Values>& qdots = {}, const detail::Same<Values>& qddots = {},
                  const std::vector<std::string>& bodies = {}, bool coriolis_matrices = false,
                  bool derivatives = false)
  {
    return derived().inverseDynamics(bodies, qs, qdots, qddots, coriolis_matrices, derivatives);
  }

  template <typename Values, detail::IfFlat<Values> = 0>
  [[deprecated("forwardDynamics(bodies, q, qdot, tau, ...): the bodies come first now")]] ForwardDynamicsResult
  forwardDynamics(const Values& q, const Values& qdot = {}, const Values& tau = {},
                  const std::vector<std::string>& bodies = {}, bool derivatives = false)
  {
    return derived().forwardDynamics(bodies, q, qdot, tau, derivatives);
  }
  template <typename Values, detail::IfEigenBatch<Values> = 0>
  [[deprecated("forwardDynamics(bodies, qs, qdots, taus, ...): the bodies come first now")]] ForwardDynamicsResult
  forwardDynamics(const Values& qs, const detail::Same<Values>& qdots = {}, const detail::Same<Values>& taus = {},
                  const std::vector<std::string>& bodies = {}, bool derivatives = false)
  {
    return derived().forwardDynamics(bodies, qs, qdots, taus, derivatives);
  }

  template <typename Names, std::enable_if_t<std::is_same<Names, std::vector<std::string>>::value, int> = 0>
  [[deprecated("frameJacobians(body, q, qdot, frames, reference, ...): qdot comes before frames now")]] FrameJacobians
  frameJacobians(const std::string& body, const std::vector<double>& q, const Names& frames,
                 FrameReference reference = FrameReference::LocalWorldAligned, const std::vector<double>& qdot = {},
                 bool acceleration_bias = false)
  {
    return derived().frameJacobians(body, q, qdot, frames, reference, acceleration_bias);
  }
  template <typename Name, std::enable_if_t<std::is_convertible<const Name&, std::string>::value, int> = 0>
  [[deprecated("frameJacobians(body, q, qdot, frames, reference, ...): qdot comes before frames now")]] FrameJacobians
  frameJacobians(const std::string& body, const std::vector<double>& q, std::initializer_list<Name> frames,
                 FrameReference reference = FrameReference::LocalWorldAligned, const std::vector<double>& qdot = {},
                 bool acceleration_bias = false)
  {
    return derived().frameJacobians(body, q, qdot, std::vector<std::string>(frames.begin(), frames.end()), reference,
                                    acceleration_bias);
  }
  /// Braced names in qdot's place, then frames: refused at compile time.
  template <typename Name, std::enable_if_t<std::is_convertible<const Name&, std::string>::value, int> = 0>
  FrameJacobians frameJacobians(const std::string& body, const std::vector<double>& q,
                                std::initializer_list<Name> names_as_qdot, const std::vector<std::string>& frames,
                                FrameReference reference = FrameReference::LocalWorldAligned,
                                bool acceleration_bias = false) = delete;
  template <std::size_t N>
  [[deprecated("frameJacobians(body, q, qdot, frames, reference, ...): qdot comes before frames now")]] FrameJacobians
  frameJacobians(const std::string& body, const std::vector<double>& q, const std::string (&frames)[N],
                 FrameReference reference = FrameReference::LocalWorldAligned, const std::vector<double>& qdot = {},
                 bool acceleration_bias = false)
  {
    return derived().frameJacobians(body, q, qdot, std::vector<std::string>(frames, frames + N), reference,
                                    acceleration_bias);
  }

private:
  Derived& derived() { return static_cast<Derived&>(*this); }
};
}  // namespace diff_rigid_body_ros
