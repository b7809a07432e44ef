// The services of rigid_body_server: the one list that the node advertises
// from and that test/rostest/service_registry.py checks the clients, the
// README and the running node against.
//
// DIFF_RIGID_BODY_SERVICES(X) calls X once per service, with
//   name            the service's name in the node's private namespace (~name)
//   srv type        diff_rigid_body::<type>, from srv/<type>.srv
//   node handler    RigidBodyServer::<handler> (src/node/rigid_body_server.h): the name in camelCase
//   python method   RigidBodyClient.<method> (src/diff_rigid_body/client.py)
//   C++ method      diff_rigid_body_ros::RigidBodyClient::<method> (rigid_body_client.h)
//   benchmark only  true: advertised only with ~benchmark_services:=true
// A client method of `none` means that no client wraps the service; only a
// benchmark-only service may have none.
//
// The list is written at configure time (cmake/service_tables.py) from the
// first line of each .srv of DRB_SERVICE_FILES (CMakeLists.txt), e.g.
//   # [service] ~get_mass_matrix; Python: mass_matrix; C++: massMatrices; core: massMatrices -> MassMatrixAnswer
// (DRB_CORE_SERVICES in service_tables.h: the services a core member answers).
// Adding a service: see docs/architecture.md ("Adding a service").
#pragma once

// Every srv type's header and DIFF_RIGID_BODY_SERVICES, generated from srv/*.srv.
#include "diff_rigid_body/services/service_messages.h"

namespace diff_rigid_body_ros
{
/// ServiceName<diff_rigid_body::Type>::value: the registry's name of each srv type (~value).
template <typename Service>
struct ServiceName;
#define DRB_SERVICE_NAME(name, type, ...)                                                                              \
  template <>                                                                                                          \
  struct ServiceName<diff_rigid_body::type>                                                                            \
  {                                                                                                                    \
    static constexpr const char* value = #name;                                                                        \
  };
DIFF_RIGID_BODY_SERVICES(DRB_SERVICE_NAME)
#undef DRB_SERVICE_NAME
}  // namespace diff_rigid_body_ros
