// The services of rigid_body_server: the one list that the node advertises
// from and that test/rostest/service_registry.py checks the clients, the
// README and the running node against.
//
// DIFF_RIGID_BODY_SERVICES(X) calls X once per service, with
//   name            the service's name in the node's private namespace (~name)
//   srv type        diff_rigid_body::<type>, from srv/<type>.srv
//   node handler    RigidBodyServer::<handler> (src/node/rigid_body_server.h)
//   python method   RigidBodyClient.<method> (src/diff_rigid_body/client.py)
//   C++ method      diff_rigid_body_ros::RigidBodyClient::<method> (rigid_body_client.h)
//   benchmark only  true: advertised only with ~benchmark_services:=true
// A client method of `none` means that no client wraps the service; only a
// benchmark-only service may have none.
//
// Adding a service: see docs/architecture.md ("Adding a service"). One entry
// per line, in the form below: the test reads this file with a regular
// expression.
#pragma once

#include <diff_rigid_body/Backprop.h>
#include <diff_rigid_body/Echo.h>
#include <diff_rigid_body/ForwardDynamics.h>
#include <diff_rigid_body/GetBodies.h>
#include <diff_rigid_body/GetCenterOfMass.h>
#include <diff_rigid_body/GetFrameJacobians.h>
#include <diff_rigid_body/GetMassMatrix.h>
#include <diff_rigid_body/GetState.h>
#include <diff_rigid_body/GetVertexJacobians.h>
#include <diff_rigid_body/GetVertexJacobiansCompact.h>
#include <diff_rigid_body/InverseDynamics.h>
#include <diff_rigid_body/Ping.h>
#include <diff_rigid_body/SetState.h>

// clang-format off
#define DIFF_RIGID_BODY_SERVICES(X)                                                                                    \
  /* name                          srv type                   node handler               python method             C++ method              benchmark only */ \
  X(get_bodies,                    GetBodies,                 getBodies,                 bodies,                   bodies,                 false) \
  X(set_state,                     SetState,                  setState,                  set_state,                setState,               false) \
  X(get_state,                     GetState,                  getState,                  get_state,                getState,               false) \
  X(get_mass_matrix,               GetMassMatrix,             getMassMatrix,             mass_matrix,              massMatrices,           false) \
  X(get_vertex_jacobians,          GetVertexJacobians,        getVertexJacobians,        vertex_jacobians,         vertexJacobians,        false) \
  X(backprop,                      Backprop,                  backprop,                  backprop,                 backprop,               false) \
  X(get_vertex_jacobians_compact,  GetVertexJacobiansCompact, getVertexJacobiansCompact, vertex_jacobians_compact, vertexJacobiansCompact, false) \
  X(inverse_dynamics,              InverseDynamics,           inverseDynamics,           inverse_dynamics,         inverseDynamics,        false) \
  X(forward_dynamics,              ForwardDynamics,           forwardDynamics,           forward_dynamics,         forwardDynamics,        false) \
  X(get_frame_jacobians,           GetFrameJacobians,         getFrameJacobians,         frame_jacobians,          frameJacobians,         false) \
  X(get_center_of_mass,            GetCenterOfMass,           getCenterOfMass,           center_of_mass,           centerOfMass,           false) \
  X(ping,                          Ping,                      ping,                      none,                     none,                   true)  \
  X(echo,                          Echo,                      echo,                      none,                     none,                   true)
// clang-format on
