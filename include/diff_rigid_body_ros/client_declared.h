// Client methods that follow from a service's declaration (its .srv's first line), for
// RigidBodyClient (rigid_body_client.h) and RigidBodyPool (rigid_body_pool.h).
//
// Every state-free service (DRB_CORE_SERVICES) can be called as query<Srv>(fields...): its request
// fields in the client argument order (the body or bodies, q, the other per-configuration fields,
// then the rest, each group in the .srv's order; docs/interface.md), each one optional from the
// first left out (empty arrays and names, false, 0, as an unset ROS request), gives its response
// (Srv::Response, flat arrays as the .srv documents them). A ServiceError carries a refusal, as
// for every call.
//
// A service whose declaration names a C++ method (DRB_CLIENT_METHODS) has that method here,
// query<Srv> under its name: `energy(bodies, q)` for `C++: energy`. A hand-written method of the
// same name in the client hides it (C++ name hiding) and keeps its richer result type, so only a
// service without one answers with its Response. The pool answers the K-configuration services
// (pool_shards.h: sharded over its instances and joined); query<GetBodies> on a pool does not
// compile (static_assert): its bodies() holds the scene it checked.
#pragma once

#include <utility>

#include "diff_rigid_body_ros/client_requests.h"
#include "diff_rigid_body_ros/services.h"

namespace diff_rigid_body_ros
{
/// The generated queries of a client `Derived`, which calls a service with `call(Srv& srv)`.
template <typename Derived>
class DeclaredQueries
{
public:
  /// State-free service Srv with its request fields set to `values`, in the client argument order
  /// (those left out at the end: empty, false, 0); returns its response.
  template <typename Srv, typename... Values>
  typename Srv::Response query(Values&&... values)
  {
    Srv srv = detail::clientRequestOf<Srv>(std::forward<Values>(values)...);
    static_cast<Derived&>(*this).call(srv);
    return std::move(srv.response);
  }

#define DRB_CLIENT_METHOD(Type, method)                                                                                \
  template <typename... Values>                                                                                        \
  diff_rigid_body::Type::Response method(Values&&... values)                                                           \
  {                                                                                                                    \
    return query<diff_rigid_body::Type>(std::forward<Values>(values)...);                                              \
  }
  DRB_CLIENT_METHODS(DRB_CLIENT_METHOD)
#undef DRB_CLIENT_METHOD
};

}  // namespace diff_rigid_body_ros
