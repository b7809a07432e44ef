// Requests of rigid_body_server's services from the client's arguments, shared by
// RigidBodyClient (rigid_body_client.h) and RigidBodyPool (rigid_body_pool.h). Field meanings and
// units: the .srv files and docs/interface.md.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "diff_rigid_body/services/service_messages.h"  // DRB_CORE_SERVICES, the srv types

namespace diff_rigid_body_ros
{
namespace detail
{
template <typename Srv>
struct ServiceTag
{
};

// requestFor(ServiceTag<Srv>, the request fields in the .srv's order) for each service a core
// member answers (DRB_CORE_SERVICES, DRB_<Type>_REQUEST_FIELDS: from each .srv's declaration);
// fields left out at the end are as in an unset request (empty, false, 0).
#define DRB_REQUEST_PARAMETER(type, name) , type name = type()
#define DRB_REQUEST_MOVE(type, name) srv.request.name = std::move(name);
// clientRequestFor: the same with the fields in the client methods' argument order
// (DRB_<Type>_CLIENT_FIELDS: the body or bodies, q, the other per-configuration fields, the rest).
#define DRB_REQUEST_BUILDER(function, Type, FIELDS)                                                                    \
  inline diff_rigid_body::Type function(ServiceTag<diff_rigid_body::Type> FIELDS(DRB_REQUEST_PARAMETER))               \
  {                                                                                                                    \
    diff_rigid_body::Type srv;                                                                                         \
    FIELDS(DRB_REQUEST_MOVE)                                                                                           \
    return srv;                                                                                                        \
  }
#define DRB_REQUEST_FOR(Type, service, handler, member, Answer)                                                        \
  DRB_REQUEST_BUILDER(requestFor, Type, DRB_##Type##_REQUEST_FIELDS)                                                   \
  DRB_REQUEST_BUILDER(clientRequestFor, Type, DRB_##Type##_CLIENT_FIELDS)
DRB_CORE_SERVICES(DRB_REQUEST_FOR)
#undef DRB_REQUEST_FOR
#undef DRB_REQUEST_BUILDER
#undef DRB_REQUEST_MOVE
#undef DRB_REQUEST_PARAMETER

/// Service `Srv` with its request's fields set to `values`, given in the .srv's order:
/// requestOf<GetMassMatrix>(bodies, q, derivatives); those left out at the end are unset.
/// Field meanings: the .srv files.
template <typename Srv, typename... Values>
Srv requestOf(Values&&... values)
{
  return requestFor(ServiceTag<Srv>{}, std::forward<Values>(values)...);
}

/// requestOf with the values in the client argument order: clientRequestOf<GetFrameJacobians>(body,
/// q, qdot, frames, reference, acceleration_bias).
template <typename Srv, typename... Values>
Srv clientRequestOf(Values&&... values)
{
  return clientRequestFor(ServiceTag<Srv>{}, std::forward<Values>(values)...);
}
}  // namespace detail
}  // namespace diff_rigid_body_ros
