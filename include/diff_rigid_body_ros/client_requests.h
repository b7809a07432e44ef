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
inline diff_rigid_body::GetMassMatrix massMatrixRequest(const std::vector<std::string>& bodies,
                                                        std::vector<double> q, bool derivatives)
{
  diff_rigid_body::GetMassMatrix srv;
  srv.request.bodies = bodies;
  srv.request.q = std::move(q);
  srv.request.derivatives = derivatives;
  return srv;
}

inline diff_rigid_body::InverseDynamics inverseDynamicsRequest(const std::vector<std::string>& bodies,
                                                               std::vector<double> q, std::vector<double> qdot,
                                                               std::vector<double> qddot, bool coriolis_matrices,
                                                               bool derivatives)
{
  diff_rigid_body::InverseDynamics srv;
  srv.request.bodies = bodies;
  srv.request.q = std::move(q);
  srv.request.qdot = std::move(qdot);
  srv.request.qddot = std::move(qddot);
  srv.request.coriolis_matrices = coriolis_matrices;
  srv.request.derivatives = derivatives;
  return srv;
}

inline diff_rigid_body::ForwardDynamics forwardDynamicsRequest(const std::vector<std::string>& bodies,
                                                               std::vector<double> q, std::vector<double> qdot,
                                                               std::vector<double> tau, bool derivatives)
{
  diff_rigid_body::ForwardDynamics srv;
  srv.request.bodies = bodies;
  srv.request.q = std::move(q);
  srv.request.qdot = std::move(qdot);
  srv.request.tau = std::move(tau);
  srv.request.derivatives = derivatives;
  return srv;
}

inline diff_rigid_body::GetVertexJacobians vertexJacobiansRequest(const std::string& body,
                                                                  const std::vector<std::uint32_t>& vertices,
                                                                  std::vector<double> q)
{
  diff_rigid_body::GetVertexJacobians srv;
  srv.request.body = body;
  srv.request.vertices = vertices;
  srv.request.q = std::move(q);
  return srv;
}

/// `gradients`: dL/dp, 3 values per vertex per configuration (client_arrays.h flattenGradients).
inline diff_rigid_body::Backprop backpropRequest(const std::string& body, const std::vector<std::uint32_t>& vertices,
                                                 std::vector<double> gradients, std::vector<double> q)
{
  diff_rigid_body::Backprop srv;
  srv.request.body = body;
  srv.request.vertices = vertices;
  srv.request.gradients = std::move(gradients);
  srv.request.q = std::move(q);
  return srv;
}
}  // namespace detail
}  // namespace diff_rigid_body_ros
