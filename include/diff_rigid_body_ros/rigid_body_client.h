// A roscpp client of rigid_body_server returning Eigen types.
//
// Header only. Persistent ServiceClients (one TCP connection per service,
// reopened once if it drops, e.g. when the node restarts). A service that
// answers success=false throws diff_rigid_body_ros::ServiceError carrying the
// node's message; a service that cannot be reached throws
// diff_rigid_body_ros::ConnectionError (at once when a dropped connection is
// not to be reopened: setReconnect(false), as RigidBodyPool does). Not
// thread-safe (persistent clients are not): use one RigidBodyClient per thread.
//
// This is the ROS layer: it lives outside include/diff_rigid_body/, the
// ROS-free core.
//
// x: a body's coordinates, d = dof values (client_types.h); a free body's x
// is q = (phi, theta, psi [rad], tx, ty, tz [m]). A single configuration is
// any Eigen vector (Vector6d for a free body, Eigen::VectorXd for any body);
// matrices are in x order.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <ros/ros.h>

#include <diff_rigid_body/Backprop.h>
#include <diff_rigid_body/BodyState.h>
#include <diff_rigid_body/ForwardDynamics.h>
#include <diff_rigid_body/GetBodies.h>
#include <diff_rigid_body/GetMassMatrix.h>
#include <diff_rigid_body/GetState.h>
#include <diff_rigid_body/GetVertexJacobians.h>
#include <diff_rigid_body/GetVertexJacobiansCompact.h>
#include <diff_rigid_body/InverseDynamics.h>
#include <diff_rigid_body/SetState.h>

#include "diff_rigid_body_ros/client_arrays.h"
#include "diff_rigid_body_ros/client_batches.h"
#include "diff_rigid_body_ros/client_declared.h"
#include "diff_rigid_body_ros/client_frames.h"
#include "diff_rigid_body_ros/client_names.h"
#include "diff_rigid_body_ros/client_requests.h"
#include "diff_rigid_body_ros/client_responses.h"

namespace diff_rigid_body_ros
{
class RigidBodyClient : public EigenBatches<RigidBodyClient>, public DeclaredQueries<RigidBodyClient>
{
public:
  /// \param server   the node's name, resolved in nh's namespace (default "rigid_body_server").
  /// \param timeout  how long to wait for a service when connecting or reconnecting; then
  ///                 ConnectionError says whether a node of that name runs ("no node at NAME ...").
  explicit RigidBodyClient(const ros::NodeHandle& nh = ros::NodeHandle(),
                           const std::string& server = "rigid_body_server",
                           ros::Duration timeout = ros::Duration(30.0))
    : nh_(nh), server_(nh.resolveName(server)), timeout_(timeout)
  {
  }

  Bodies bodies()
  {
    diff_rigid_body::GetBodies srv;
    call("get_bodies", srv);
    return toBodies(srv.response);
  }

  /// States of `bodies` (empty = all), in the node's order.
  BodyStates getState(const std::vector<std::string>& bodies = {})
  {
    diff_rigid_body::GetState srv;
    srv.request.bodies = bodies;
    call("get_state", srv);
    BodyStates out;
    for (const auto& state : srv.response.states)
      out.emplace_back(state.name, Eigen::Map<const Eigen::VectorXd>(state.q.data(), state.q.size()));
    return out;
  }

  /// All or nothing. (name, q) pairs of free bodies, or (name, x) pairs of any
  /// bodies (e.g. a BodyStates).
  void setState(const std::vector<std::pair<std::string, Vector6d>>& states) { requestSetState(states); }
  template <typename Vector, typename = std::enable_if_t<!std::is_same<Vector, Vector6d>::value>>
  void setState(const std::vector<std::pair<std::string, Vector>>& states)
  {
    requestSetState(states);
  }
  template <typename Derived>
  void setState(const std::string& body, const Eigen::MatrixBase<Derived>& x)
  {
    setState(std::vector<std::pair<std::string, Eigen::VectorXd>>{ { body, x } });
  }

  /// M(x) of `bodies` (empty = all). `q`: empty = the current state, else K
  /// configurations, each the concatenation of the n bodies' x (K*6*n values
  /// for free bodies). The node's state is not changed.
  MassMatrices massMatrices(const std::vector<std::string>& bodies = {}, const std::vector<double>& q = {},
                            bool derivatives = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::GetMassMatrix>(bodies, q, derivatives);
    call("get_mass_matrix", srv);
    return toMassMatrices(srv.response, derivatives);
  }
  using EigenBatches<RigidBodyClient>::massMatrices;  // K configurations as std::vector<Vector6d or VectorXd>

  /// M of one body at x (one configuration): d x d.
  template <typename Derived>
  Eigen::MatrixXd massMatrix(const std::string& body, const Eigen::MatrixBase<Derived>& x)
  {
    return massMatrices({ body }, detail::values(x)).M.at(0);
  }

  /// tau = M(x) x'' + c(x, x') + g(x) [N m, N] of `bodies` (empty = all) at K configurations:
  /// `q` as for massMatrices (empty = the current state, K = 1), `qdot` [rad/s, m/s] and `qddot`
  /// [rad/s^2, m/s^2] of q's length (for an empty q: the bodies' D values) or empty (zeros).
  /// `coriolis_matrices` adds C, `derivatives` dtau/dx and dtau/dx'. Defined at gimbal lock too.
  InverseDynamicsResult inverseDynamics(const std::vector<std::string>& bodies = {},
                                        const std::vector<double>& q = {}, const std::vector<double>& qdot = {},
                                        const std::vector<double>& qddot = {}, bool coriolis_matrices = false,
                                        bool derivatives = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::InverseDynamics>(bodies, q, qdot, qddot, coriolis_matrices,
                                                                   derivatives);
    call("inverse_dynamics", srv);
    return toInverseDynamics(srv.response);
  }
  using EigenBatches<RigidBodyClient>::inverseDynamics;

  /// x'' = M(x)^-1 (tau - c(x, x') - g(x)) [rad/s^2, m/s^2] of `bodies` (empty = all), laid out as
  /// inverseDynamics (`tau` [N m, N] in place of qddot); `derivatives` adds dx''/dx, dx''/dx' and
  /// dx''/dtau = M^-1. A configuration where M is singular (gimbal lock, a coordinate that moves
  /// no mass) throws ServiceError naming the body and the configuration.
  ForwardDynamicsResult forwardDynamics(const std::vector<std::string>& bodies = {},
                                        const std::vector<double>& q = {}, const std::vector<double>& qdot = {},
                                        const std::vector<double>& tau = {}, bool derivatives = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::ForwardDynamics>(bodies, q, qdot, tau, derivatives);
    call("forward_dynamics", srv);
    return toForwardDynamics(srv.response);
  }
  using EigenBatches<RigidBodyClient>::forwardDynamics;

  /// Poses and Jacobians (client_frames.h) of `body`'s link `frames` (empty = every link of the
  /// body) at K configurations: `q` K d values (empty = the current state), `qdot` q's length or
  /// empty (zeros, for the acceleration bias J'x'). The node's state is not changed.
  FrameJacobians frameJacobians(const std::string& body, const std::vector<double>& q = {},
                                const std::vector<double>& qdot = {}, const std::vector<std::string>& frames = {},
                                FrameReference reference = FrameReference::LocalWorldAligned,
                                bool acceleration_bias = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::GetFrameJacobians>(
        body, frames, q, qdot, static_cast<std::uint8_t>(reference), acceleration_bias);
    call("get_frame_jacobians", srv);
    return toFrameJacobians(srv.response);
  }
  using EigenBatches<RigidBodyClient>::frameJacobians;  // the earlier order (client_earlier_orders.h)

  /// The centre of mass of `bodies` (empty = all), laid out as massMatrices; `jacobians` adds
  /// dc/dx and the acceleration bias J'x' at `qdot` (q's length, or empty: zeros).
  CenterOfMassResult centerOfMass(const std::vector<std::string>& bodies = {}, const std::vector<double>& q = {},
                                  const std::vector<double>& qdot = {}, bool jacobians = false)
  {
    auto srv = detail::requestOf<diff_rigid_body::GetCenterOfMass>(bodies, q, qdot, jacobians);
    call("get_center_of_mass", srv);
    return toCenterOfMass(srv.response);
  }

  /// Positions and J = dp/dx of `body`'s `vertices` (empty = all) at `q`
  /// (nullptr = the current state) or at x.
  VertexJacobians vertexJacobians(const std::string& body, const Vector6d* q = nullptr,
                                  const std::vector<std::uint32_t>& vertices = {})
  {
    return requestVertexJacobians(body, vertices, detail::optionalQ(q), 1).front();
  }
  template <typename Derived>
  VertexJacobians vertexJacobians(const std::string& body, const Eigen::MatrixBase<Derived>& x,
                                  const std::vector<std::uint32_t>& vertices = {})
  {
    return requestVertexJacobians(body, vertices, detail::values(x), 1).front();
  }
  /// K configurations in one call: positions and J of `body`'s `vertices`
  /// (empty = all) at each x of `qs`, block k for qs[k] (the same bits as a
  /// call with qs[k] alone). The node's state is not changed.
  std::vector<VertexJacobians> vertexJacobians(const std::string& body, const std::vector<Vector6d>& qs,
                                               const std::vector<std::uint32_t>& vertices = {})
  {
    return requestVertexJacobians(body, vertices, detail::flatten(qs), qs.size());
  }
  std::vector<VertexJacobians> vertexJacobians(const std::string& body, const std::vector<Eigen::VectorXd>& qs,
                                               const std::vector<std::uint32_t>& vertices = {})
  {
    return requestVertexJacobians(body, vertices, detail::flatten(qs), qs.size());
  }

  /// dL/dx (d values) from dL/dp (3 x N, column v for vertex v) of `body`'s
  /// `vertices` (empty = all) at `q` (nullptr = the current state) or at x.
  /// J is never formed.
  Eigen::VectorXd backprop(const std::string& body, const Eigen::Matrix3Xd& gradients, const Vector6d* q = nullptr,
                           const std::vector<std::uint32_t>& vertices = {})
  {
    return requestBackprop(body, vertices, { &gradients }, detail::optionalQ(q), 1).front();
  }
  template <typename Derived>
  Eigen::VectorXd backprop(const std::string& body, const Eigen::Matrix3Xd& gradients,
                           const Eigen::MatrixBase<Derived>& x, const std::vector<std::uint32_t>& vertices = {})
  {
    return requestBackprop(body, vertices, { &gradients }, detail::values(x), 1).front();
  }
  /// K configurations in one call: dL/dx at each x of `qs` from dL_dp[k]
  /// (3 x N, column v for vertex v) at qs[k]; entry k has the same bits as a
  /// call with dL_dp[k] and qs[k] alone. dL_dp and qs have the same size.
  std::vector<Vector6d> backprop(const std::string& body, const std::vector<Eigen::Matrix3Xd>& dL_dp,
                                 const std::vector<Vector6d>& qs, const std::vector<std::uint32_t>& vertices = {})
  {
    const std::vector<Eigen::VectorXd> out = batchedBackprop(body, dL_dp, detail::flatten(qs), qs.size(), vertices);
    return std::vector<Vector6d>(out.begin(), out.end());
  }
  std::vector<Eigen::VectorXd> backprop(const std::string& body, const std::vector<Eigen::Matrix3Xd>& dL_dp,
                                        const std::vector<Eigen::VectorXd>& qs,
                                        const std::vector<std::uint32_t>& vertices = {})
  {
    return batchedBackprop(body, dL_dp, detail::flatten(qs), qs.size(), vertices);
  }

  /// The reduced transport of vertexJacobians: positions and the columns
  /// of J that are not always I3 (none with `positions_only`) of `body`'s
  /// `vertices` (empty = all) at `q` (nullptr = the current state) or at x.
  /// Scalar = float asks the node for the float32 fields (single_precision).
  template <typename Scalar = double>
  VertexRotationJacobians<Scalar> vertexJacobiansCompact(const std::string& body, const Vector6d* q = nullptr,
                                                         const std::vector<std::uint32_t>& vertices = {},
                                                         bool positions_only = false)
  {
    return requestCompact<Scalar>(body, vertices, detail::optionalQ(q), 1, positions_only).front();
  }
  template <typename Scalar = double, typename Derived>
  VertexRotationJacobians<Scalar> vertexJacobiansCompact(const std::string& body, const Eigen::MatrixBase<Derived>& x,
                                                         const std::vector<std::uint32_t>& vertices = {},
                                                         bool positions_only = false)
  {
    return requestCompact<Scalar>(body, vertices, detail::values(x), 1, positions_only).front();
  }
  /// K configurations in one call: block k for qs[k], as vertexJacobians.
  template <typename Scalar = double, typename Vector>
  std::vector<VertexRotationJacobians<Scalar>> vertexJacobiansCompact(const std::string& body,
                                                                      const std::vector<Vector>& qs,
                                                                      const std::vector<std::uint32_t>& vertices = {},
                                                                      bool positions_only = false)
  {
    return requestCompact<Scalar>(body, vertices, detail::flatten(qs), qs.size(), positions_only);
  }

  const std::string& server() const { return server_; }
  /// false: a call whose connection drops throws ConnectionError at once instead of reconnecting
  /// once and retrying (the next call connects again, waiting up to the timeout).
  void setReconnect(bool reconnect) { reconnect_ = reconnect; }

  /// Calls ~`service` (of the registry, services.h) with `srv` over its persistent connection;
  /// throws ServiceError on success=false, ConnectionError when the node cannot be reached.
  template <typename Service>
  void call(const std::string& service, Service& srv)
  {
    ros::ServiceClient& client = connections_[service];
    if (!client || !client.isValid())
      connect<Service>(client, service);
    if (!client.call(srv))
    {
      client = ros::ServiceClient();  // dropped: the next call opens a new connection
      if (!reconnect_)
        throw ConnectionError("service " + server_ + "/" + service + " failed (connection lost)");
      connect<Service>(client, service);
      if (!client.call(srv))
        throw ConnectionError("service " + server_ + "/" + service + " failed after reconnecting");
    }
    if (!srv.response.success)
      throw ServiceError(server_ + "/" + service, srv.response.message);
  }
  /// call(name, srv) with the service's registry name (services.h).
  template <typename Service>
  void call(Service& srv)
  {
    call(ServiceName<Service>::value, srv);
  }

private:
  template <typename Service>
  void connect(ros::ServiceClient& client, const std::string& service)
  {
    const std::string name = server_ + "/" + service;
    if (!ros::service::waitForService(name, timeout_))
      throw ConnectionError(detail::missingNodeMessage(server_, name, timeout_.toSec()));
    client = nh_.serviceClient<Service>(name, /*persistent=*/true);
  }

  template <typename Vector>
  void requestSetState(const std::vector<std::pair<std::string, Vector>>& states)
  {
    diff_rigid_body::SetState srv;
    for (const auto& named : states)
    {
      diff_rigid_body::BodyState state;
      state.name = named.first;
      state.q = detail::values(named.second);
      srv.request.states.push_back(std::move(state));
    }
    call("set_state", srv);
  }

  /// get_vertex_jacobians with `q` holding K configurations (or empty: the current state, K = 1).
  std::vector<VertexJacobians> requestVertexJacobians(const std::string& body,
                                                      const std::vector<std::uint32_t>& vertices,
                                                      std::vector<double> q, std::size_t K)
  {
    auto srv = detail::requestOf<diff_rigid_body::GetVertexJacobians>(body, vertices, std::move(q));
    call("get_vertex_jacobians", srv);
    return toVertexJacobians(srv.response, K);
  }

  std::vector<Eigen::VectorXd> batchedBackprop(const std::string& body, const std::vector<Eigen::Matrix3Xd>& dL_dp,
                                               std::vector<double> q, std::size_t K,
                                               const std::vector<std::uint32_t>& vertices)
  {
    if (dL_dp.size() != K)
      throw std::invalid_argument("backprop: " + std::to_string(dL_dp.size()) + " gradient blocks for " +
                                  std::to_string(K) + " configurations");
    std::vector<const Eigen::Matrix3Xd*> blocks;
    for (const Eigen::Matrix3Xd& gradients : dL_dp)
      blocks.push_back(&gradients);
    return requestBackprop(body, vertices, blocks, std::move(q), K);
  }

  /// backprop with one 3 x N gradient block per configuration of `q`.
  std::vector<Eigen::VectorXd> requestBackprop(const std::string& body, const std::vector<std::uint32_t>& vertices,
                                               const std::vector<const Eigen::Matrix3Xd*>& dL_dp,
                                               std::vector<double> q, std::size_t K)
  {
    auto srv = detail::requestOf<diff_rigid_body::Backprop>(body, vertices, detail::flattenGradients(dL_dp),
                                                            std::move(q));
    call("backprop", srv);
    return toGradients(srv.response, K);
  }

  /// get_vertex_jacobians_compact in Scalar (float: single_precision), K configurations in `q`.
  template <typename Scalar>
  std::vector<VertexRotationJacobians<Scalar>> requestCompact(const std::string& body,
                                                              const std::vector<std::uint32_t>& vertices,
                                                              std::vector<double> q, std::size_t K,
                                                              bool positions_only)
  {
    static_assert(std::is_same<Scalar, double>::value || std::is_same<Scalar, float>::value,
                  "vertexJacobiansCompact: Scalar is double or float");
    diff_rigid_body::GetVertexJacobiansCompact srv;
    srv.request.body = body;
    srv.request.vertices = vertices;
    srv.request.q = std::move(q);
    srv.request.positions_only = positions_only;
    srv.request.single_precision = std::is_same<Scalar, float>::value;
    call("get_vertex_jacobians_compact", srv);
    return toRotationJacobians<Scalar>(srv.response, K, positions_only);
  }

  ros::NodeHandle nh_;
  std::string server_;
  ros::Duration timeout_;
  bool reconnect_ = true;
  std::map<std::string, ros::ServiceClient> connections_;  ///< service name -> its persistent connection
};

}  // namespace diff_rigid_body_ros
