// Requests of rigid_body_server's services from the client's arguments, shared by
// RigidBodyClient (rigid_body_client.h) and RigidBodyPool (rigid_body_pool.h). Field meanings and
// units: the .srv files and docs/interface.md.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <diff_rigid_body/Backprop.h>
#include <diff_rigid_body/ForwardDynamics.h>
#include <diff_rigid_body/GetMassMatrix.h>
#include <diff_rigid_body/GetVertexJacobians.h>
#include <diff_rigid_body/InverseDynamics.h>

namespace diff_rigid_body_ros
{
namespace detail
{
/// A service `Srv` whose request holds the given fields: requestOf<Srv>(&Request::a, value_a,
/// &Request::b, value_b, ...) assigns each value to its field, in order; fields not named keep
/// their message defaults (empty arrays, false, 0).
template <typename Request>
void assignFields(Request& /*request*/)
{
}

template <typename Request, typename Field, typename Value, typename... Rest>
void assignFields(Request& request, Field Request::*field, Value&& value, Rest&&... rest)
{
  request.*field = static_cast<Field>(std::forward<Value>(value));
  assignFields(request, std::forward<Rest>(rest)...);
}

template <typename Srv, typename... Fields>
Srv requestOf(Fields&&... fields)
{
  Srv srv;
  assignFields(srv.request, std::forward<Fields>(fields)...);
  return srv;
}

inline diff_rigid_body::GetMassMatrix massMatrixRequest(const std::vector<std::string>& bodies,
                                                        std::vector<double> q, bool derivatives)
{
  using R = diff_rigid_body::GetMassMatrix::Request;
  return requestOf<diff_rigid_body::GetMassMatrix>(&R::bodies, bodies, &R::q, std::move(q), &R::derivatives,
                                                   derivatives);
}

inline diff_rigid_body::InverseDynamics inverseDynamicsRequest(const std::vector<std::string>& bodies,
                                                               std::vector<double> q, std::vector<double> qdot,
                                                               std::vector<double> qddot, bool coriolis_matrices,
                                                               bool derivatives)
{
  using R = diff_rigid_body::InverseDynamics::Request;
  return requestOf<diff_rigid_body::InverseDynamics>(&R::bodies, bodies, &R::q, std::move(q), &R::qdot,
                                                     std::move(qdot), &R::qddot, std::move(qddot),
                                                     &R::coriolis_matrices, coriolis_matrices, &R::derivatives,
                                                     derivatives);
}

inline diff_rigid_body::ForwardDynamics forwardDynamicsRequest(const std::vector<std::string>& bodies,
                                                               std::vector<double> q, std::vector<double> qdot,
                                                               std::vector<double> tau, bool derivatives)
{
  using R = diff_rigid_body::ForwardDynamics::Request;
  return requestOf<diff_rigid_body::ForwardDynamics>(&R::bodies, bodies, &R::q, std::move(q), &R::qdot,
                                                     std::move(qdot), &R::tau, std::move(tau), &R::derivatives,
                                                     derivatives);
}

inline diff_rigid_body::GetVertexJacobians vertexJacobiansRequest(const std::string& body,
                                                                  const std::vector<std::uint32_t>& vertices,
                                                                  std::vector<double> q)
{
  using R = diff_rigid_body::GetVertexJacobians::Request;
  return requestOf<diff_rigid_body::GetVertexJacobians>(&R::body, body, &R::vertices, vertices, &R::q, std::move(q));
}

/// `gradients`: dL/dp, 3 values per vertex per configuration (client_arrays.h flattenGradients).
inline diff_rigid_body::Backprop backpropRequest(const std::string& body, const std::vector<std::uint32_t>& vertices,
                                                 std::vector<double> gradients, std::vector<double> q)
{
  using R = diff_rigid_body::Backprop::Request;
  return requestOf<diff_rigid_body::Backprop>(&R::body, body, &R::vertices, vertices, &R::gradients,
                                              std::move(gradients), &R::q, std::move(q));
}
}  // namespace detail
}  // namespace diff_rigid_body_ros
