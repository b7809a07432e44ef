// A roscpp client of rigid_body_server returning Eigen types.
//
// Header only. Persistent ServiceClients (one TCP connection per service,
// reopened once if it drops, e.g. when the node restarts). A service that
// answers success=false throws diff_rigid_body_ros::ServiceError carrying the
// node's message; a service that cannot be reached throws
// diff_rigid_body_ros::ConnectionError. Not thread-safe (persistent clients
// are not): use one RigidBodyClient per thread.
//
// This is the ROS layer: it lives outside include/diff_rigid_body/, the
// ROS-free core.
//
// q = (phi, theta, psi [rad], tx, ty, tz [m]); matrices in q order.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <ros/ros.h>

#include <diff_rigid_body/Backprop.h>
#include <diff_rigid_body/BodyState.h>
#include <diff_rigid_body/GetBodies.h>
#include <diff_rigid_body/GetMassMatrix.h>
#include <diff_rigid_body/GetState.h>
#include <diff_rigid_body/GetVertexJacobians.h>
#include <diff_rigid_body/GetVertexJacobiansCompact.h>
#include <diff_rigid_body/SetState.h>

namespace diff_rigid_body_ros
{
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
/// Stacked vertex Jacobians: rows 3v..3v+2 are J_v = dp_v/dq (3x6).
using StackedJacobians = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

/// A service answered success=false. message() is the node's explanation
/// (it names the body, index or field); the node's state is unchanged.
class ServiceError : public std::runtime_error
{
public:
  ServiceError(const std::string& service, const std::string& message)
    : std::runtime_error(service + ": " + message), service_(service), message_(message)
  {
  }
  const std::string& service() const { return service_; }
  const std::string& message() const { return message_; }

private:
  std::string service_;
  std::string message_;
};

/// A service could not be reached (not advertised within the timeout, or the
/// call failed again after reconnecting).
class ConnectionError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// One link of a body (get_bodies), in vertex order.
struct Link
{
  std::string name;
  double mass = 0.0;                                  ///< [kg], 0 for a massless frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< [kg m^2] about its COM, link axes
  Eigen::Vector3d com_offset = Eigen::Vector3d::Zero();  ///< [m] its COM in its frame
  std::uint32_t first_vertex = 0;  ///< its vertices: first_vertex .. first_vertex + vertex_count - 1
  std::uint32_t vertex_count = 0;
};

/// get_bodies.
struct Bodies
{
  std::string fixed_frame;
  std::vector<std::string> names;
  std::vector<double> masses;                     ///< [kg]
  std::vector<Eigen::Matrix3d> inertias;          ///< [kg m^2] about the COM, body axes
  std::vector<Eigen::Vector3d> com_offsets;       ///< [m] the COM in the link frame
  std::vector<std::uint32_t> vertex_counts;
  std::vector<std::uint32_t> dofs;                ///< len(x) per body
  std::vector<std::vector<std::string>> joint_names;  ///< per body, in x order
  std::vector<std::vector<Link>> links;           ///< per body, in vertex order
};

/// get_mass_matrix: K configurations of n bodies.
struct MassMatrices
{
  std::vector<std::string> bodies;             ///< the n bodies, in answer order
  std::size_t configurations = 0;              ///< K
  std::vector<Matrix6d> M;                     ///< K*n matrices; configuration k, body i at k*n + i
  std::vector<std::array<Matrix6d, 6>> dM;     ///< with derivatives: dM[k*n + i][j] = dM/dq_j
  std::vector<double> cos_theta;               ///< gimbal-lock diagnostic, one per matrix

  const Matrix6d& at(std::size_t k, std::size_t i) const { return M.at(k * bodies.size() + i); }
};

/// get_vertex_jacobians.
struct VertexJacobians
{
  Eigen::Matrix3Xd positions;  ///< [m] column v = vertex v in the fixed frame
  StackedJacobians J;          ///< 3N x 6; J.middleRows<3>(3 * v) = dp_v/dq

  Eigen::Matrix<double, 3, 6> jacobian(Eigen::Index v) const { return J.middleRows<3>(3 * v); }
};

/// get_vertex_jacobians_compact, in Scalar = double or float (the float32
/// transport: the double values rounded to float32). J_v = [ Jr_v | I3 ]:
/// only the rotation block Jr_v = dp_v/d(phi, theta, psi) is sent.
template <typename Scalar>
struct VertexRotationJacobians
{
  using StackedRotationJacobians = Eigen::Matrix<Scalar, Eigen::Dynamic, 3, Eigen::RowMajor>;
  Eigen::Matrix<Scalar, 3, Eigen::Dynamic> positions;  ///< [m] column v = vertex v in the fixed frame
  StackedRotationJacobians Jr;  ///< 3N x 3; Jr.middleRows<3>(3 * v) = Jr_v; 0 x 3 with positions_only

  Eigen::Matrix<Scalar, 3, 3> rotationJacobian(Eigen::Index v) const { return Jr.template middleRows<3>(3 * v); }
};

class RigidBodyClient
{
public:
  /// \param server   the node's name, resolved in nh's namespace (default "rigid_body_server").
  /// \param timeout  how long to wait for a service when connecting or reconnecting.
  explicit RigidBodyClient(const ros::NodeHandle& nh = ros::NodeHandle(),
                           const std::string& server = "rigid_body_server",
                           ros::Duration timeout = ros::Duration(30.0))
    : nh_(nh), server_(nh.resolveName(server)), timeout_(timeout)
  {
  }

  Bodies bodies()
  {
    diff_rigid_body::GetBodies srv;
    call(get_bodies_, "get_bodies", srv);
    Bodies out;
    out.fixed_frame = srv.response.fixed_frame;
    out.names = srv.response.names;
    out.masses = srv.response.masses;
    out.vertex_counts = srv.response.vertex_counts;
    out.dofs = srv.response.dofs;
    for (std::size_t i = 0; i < out.names.size(); ++i)
    {
      out.inertias.push_back(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
          srv.response.inertias.data() + 9 * i));
      out.com_offsets.push_back(Eigen::Map<const Eigen::Vector3d>(srv.response.com_offsets.data() + 3 * i));
    }
    std::size_t joint = 0;
    for (std::uint32_t count : srv.response.joint_counts)
    {
      out.joint_names.emplace_back(srv.response.joint_names.begin() + joint,
                                   srv.response.joint_names.begin() + joint + count);
      joint += count;
    }
    std::size_t link = 0;
    for (std::uint32_t count : srv.response.link_counts)
    {
      std::vector<Link> links;
      std::uint32_t first_vertex = 0;
      for (std::uint32_t k = 0; k < count; ++k, ++link)
      {
        Link l;
        l.name = srv.response.link_names[link];
        l.mass = srv.response.link_masses[link];
        l.inertia = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
            srv.response.link_inertias.data() + 9 * link);
        l.com_offset = Eigen::Map<const Eigen::Vector3d>(srv.response.link_com_offsets.data() + 3 * link);
        l.first_vertex = first_vertex;
        l.vertex_count = srv.response.link_vertex_counts[link];
        first_vertex += l.vertex_count;
        links.push_back(std::move(l));
      }
      out.links.push_back(std::move(links));
    }
    return out;
  }

  /// States of `bodies` (empty = all), in the node's order.
  std::vector<std::pair<std::string, Vector6d>> getState(const std::vector<std::string>& bodies = {})
  {
    diff_rigid_body::GetState srv;
    srv.request.bodies = bodies;
    call(get_state_, "get_state", srv);
    std::vector<std::pair<std::string, Vector6d>> out;
    for (const auto& state : srv.response.states)
      out.emplace_back(state.name, Eigen::Map<const Vector6d>(state.q.data()));
    return out;
  }

  /// All or nothing.
  void setState(const std::vector<std::pair<std::string, Vector6d>>& states)
  {
    diff_rigid_body::SetState srv;
    for (const auto& named : states)
    {
      diff_rigid_body::BodyState state;
      state.name = named.first;
      Eigen::Map<Vector6d>(state.q.data()) = named.second;
      srv.request.states.push_back(state);
    }
    call(set_state_, "set_state", srv);
  }
  void setState(const std::string& body, const Vector6d& q) { setState({ { body, q } }); }

  /// M(q) of `bodies` (empty = all). `q`: empty = the current state, else K
  /// configurations of the n bodies, K*6*n values (configuration k, body i at
  /// (k*n + i)*6). The node's state is not changed.
  MassMatrices massMatrices(const std::vector<std::string>& bodies = {}, const std::vector<double>& q = {},
                            bool derivatives = false)
  {
    diff_rigid_body::GetMassMatrix srv;
    srv.request.bodies = bodies;
    srv.request.q = q;
    srv.request.derivatives = derivatives;
    call(get_mass_matrix_, "get_mass_matrix", srv);
    const auto& r = srv.response;
    MassMatrices out;
    out.bodies = r.bodies;
    const std::size_t count = r.mass_matrices.size() / 36;
    out.configurations = out.bodies.empty() ? 0 : count / out.bodies.size();
    out.M.reserve(count);
    for (std::size_t m = 0; m < count; ++m)
      out.M.push_back(Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(r.mass_matrices.data() + 36 * m));
    if (derivatives)
    {
      out.dM.resize(count);
      for (std::size_t m = 0; m < count; ++m)
        for (int j = 0; j < 6; ++j)
          out.dM[m][j] =
              Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(r.derivatives.data() + 216 * m + 36 * j);
    }
    out.cos_theta = r.cos_theta;
    return out;
  }

  /// M of one body at q (one configuration).
  Matrix6d massMatrix(const std::string& body, const Vector6d& q)
  {
    return massMatrices({ body }, std::vector<double>(q.data(), q.data() + 6)).M.at(0);
  }

  /// Positions and J = dp/dq of `body`'s `vertices` (empty = all) at `q`
  /// (nullptr = the current state).
  VertexJacobians vertexJacobians(const std::string& body, const Vector6d* q = nullptr,
                                  const std::vector<std::uint32_t>& vertices = {})
  {
    return requestVertexJacobians(body, vertices, optionalQ(q), 1).front();
  }
  VertexJacobians vertexJacobians(const std::string& body, const Vector6d& q,
                                  const std::vector<std::uint32_t>& vertices = {})
  {
    return vertexJacobians(body, &q, vertices);
  }
  /// K configurations in one call: positions and J of `body`'s `vertices`
  /// (empty = all) at each q of `qs`, block k for qs[k] (the same bits as a
  /// call with qs[k] alone). The node's state is not changed.
  std::vector<VertexJacobians> vertexJacobians(const std::string& body, const std::vector<Vector6d>& qs,
                                               const std::vector<std::uint32_t>& vertices = {})
  {
    return requestVertexJacobians(body, vertices, flatten(qs), qs.size());
  }

  /// dL/dq from dL/dp (3 x N, column v for vertex v) of `body`'s `vertices`
  /// (empty = all) at `q` (nullptr = the current state). J is never formed.
  Vector6d backprop(const std::string& body, const Eigen::Matrix3Xd& gradients, const Vector6d* q = nullptr,
                    const std::vector<std::uint32_t>& vertices = {})
  {
    return requestBackprop(body, vertices, { &gradients }, optionalQ(q), 1).front();
  }
  Vector6d backprop(const std::string& body, const Eigen::Matrix3Xd& gradients, const Vector6d& q,
                    const std::vector<std::uint32_t>& vertices = {})
  {
    return backprop(body, gradients, &q, vertices);
  }
  /// K configurations in one call: dL/dq at each q of `qs` from dL_dp[k]
  /// (3 x N, column v for vertex v) at qs[k]; entry k has the same bits as a
  /// call with dL_dp[k] and qs[k] alone. dL_dp and qs have the same size.
  std::vector<Vector6d> backprop(const std::string& body, const std::vector<Eigen::Matrix3Xd>& dL_dp,
                                 const std::vector<Vector6d>& qs, const std::vector<std::uint32_t>& vertices = {})
  {
    if (dL_dp.size() != qs.size())
      throw std::invalid_argument("backprop: " + std::to_string(dL_dp.size()) + " gradient blocks for " +
                                  std::to_string(qs.size()) + " configurations");
    std::vector<const Eigen::Matrix3Xd*> blocks;
    for (const Eigen::Matrix3Xd& gradients : dL_dp)
      blocks.push_back(&gradients);
    return requestBackprop(body, vertices, blocks, flatten(qs), qs.size());
  }

  /// The reduced transport of vertexJacobians: positions and the rotation
  /// blocks Jr (none with `positions_only`) of `body`'s `vertices` (empty =
  /// all) at `q` (nullptr = the current state). Scalar = float asks the node
  /// for the float32 fields (single_precision).
  template <typename Scalar = double>
  VertexRotationJacobians<Scalar> vertexJacobiansCompact(const std::string& body, const Vector6d* q = nullptr,
                                                         const std::vector<std::uint32_t>& vertices = {},
                                                         bool positions_only = false)
  {
    return requestCompact<Scalar>(body, vertices, optionalQ(q), 1, positions_only).front();
  }
  template <typename Scalar = double>
  VertexRotationJacobians<Scalar> vertexJacobiansCompact(const std::string& body, const Vector6d& q,
                                                         const std::vector<std::uint32_t>& vertices = {},
                                                         bool positions_only = false)
  {
    return vertexJacobiansCompact<Scalar>(body, &q, vertices, positions_only);
  }
  /// K configurations in one call: block k for qs[k], as vertexJacobians.
  template <typename Scalar = double>
  std::vector<VertexRotationJacobians<Scalar>> vertexJacobiansCompact(const std::string& body,
                                                                      const std::vector<Vector6d>& qs,
                                                                      const std::vector<std::uint32_t>& vertices = {},
                                                                      bool positions_only = false)
  {
    return requestCompact<Scalar>(body, vertices, flatten(qs), qs.size(), positions_only);
  }

  const std::string& server() const { return server_; }

private:
  template <typename Service>
  void connect(ros::ServiceClient& client, const std::string& service)
  {
    const std::string name = server_ + "/" + service;
    if (!ros::service::waitForService(name, timeout_))
      throw ConnectionError("service " + name + " is not advertised (waited " + std::to_string(timeout_.toSec()) +
                            " s)");
    client = nh_.serviceClient<Service>(name, /*persistent=*/true);
  }

  /// Calls over the persistent connection; reconnects once if it dropped.
  template <typename Service>
  void call(ros::ServiceClient& client, const std::string& service, Service& srv)
  {
    if (!client || !client.isValid())
      connect<Service>(client, service);
    if (!client.call(srv))
    {
      connect<Service>(client, service);
      if (!client.call(srv))
        throw ConnectionError("service " + server_ + "/" + service + " failed after reconnecting");
    }
    if (!srv.response.success)
      throw ServiceError(server_ + "/" + service, srv.response.message);
  }

  /// get_vertex_jacobians with `q` holding K configurations (or empty: the current state, K = 1).
  std::vector<VertexJacobians> requestVertexJacobians(const std::string& body,
                                                      const std::vector<std::uint32_t>& vertices,
                                                      std::vector<double> q, std::size_t K)
  {
    diff_rigid_body::GetVertexJacobians srv;
    srv.request.body = body;
    srv.request.vertices = vertices;
    srv.request.q = std::move(q);
    call(get_vertex_jacobians_, "get_vertex_jacobians", srv);
    const auto& r = srv.response;
    const Eigen::Index n = vertexCount(r.positions.size(), K);
    std::vector<VertexJacobians> out(K);
    for (std::size_t k = 0; k < K; ++k)
    {
      out[k].positions = Eigen::Map<const Eigen::Matrix3Xd>(r.positions.data() + 3 * n * k, 3, n);
      out[k].J = Eigen::Map<const StackedJacobians>(r.jacobians.data() + 18 * n * k, 3 * n, 6);
    }
    return out;
  }

  /// backprop with one 3 x N gradient block per configuration of `q`.
  std::vector<Vector6d> requestBackprop(const std::string& body, const std::vector<std::uint32_t>& vertices,
                                        const std::vector<const Eigen::Matrix3Xd*>& dL_dp, std::vector<double> q,
                                        std::size_t K)
  {
    diff_rigid_body::Backprop srv;
    srv.request.body = body;
    srv.request.vertices = vertices;
    for (const Eigen::Matrix3Xd* gradients : dL_dp)
      srv.request.gradients.insert(srv.request.gradients.end(), gradients->data(),
                                   gradients->data() + gradients->size());
    srv.request.q = std::move(q);
    call(backprop_, "backprop", srv);
    std::vector<Vector6d> out(K);
    for (std::size_t k = 0; k < K; ++k)
      out[k] = Eigen::Map<const Vector6d>(srv.response.gradient.data() + 6 * k);
    return out;
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
    call(get_vertex_jacobians_compact_, "get_vertex_jacobians_compact", srv);
    const auto& r = srv.response;
    const std::vector<Scalar>& positions = compactField<Scalar>(r.positions, r.positions_f32);
    const std::vector<Scalar>& jacobians = compactField<Scalar>(r.rotation_jacobians, r.rotation_jacobians_f32);
    const Eigen::Index n = vertexCount(positions.size(), K);
    const Eigen::Index rows = positions_only ? 0 : 3 * n;
    std::vector<VertexRotationJacobians<Scalar>> out(K);
    for (std::size_t k = 0; k < K; ++k)
    {
      out[k].positions = Eigen::Map<const Eigen::Matrix<Scalar, 3, Eigen::Dynamic>>(positions.data() + 3 * n * k, 3, n);
      out[k].Jr = Eigen::Map<const typename VertexRotationJacobians<Scalar>::StackedRotationJacobians>(
          jacobians.data() + 3 * rows * k, rows, 3);
    }
    return out;
  }

  /// A single request's q: empty (the current state) or the 6 values of *q.
  static std::vector<double> optionalQ(const Vector6d* q)
  {
    return q ? std::vector<double>(q->data(), q->data() + 6) : std::vector<double>();
  }

  /// The 6 K values of a batched request's q (K >= 1: an empty q would mean the current state).
  static std::vector<double> flatten(const std::vector<Vector6d>& qs)
  {
    if (qs.empty())
      throw std::invalid_argument("qs: at least one configuration");
    std::vector<double> q;
    q.reserve(6 * qs.size());
    for (const Vector6d& one : qs)
      q.insert(q.end(), one.data(), one.data() + 6);
    return q;
  }

  /// N from the size of a K x N x 3 positions field.
  static Eigen::Index vertexCount(std::size_t position_values, std::size_t configurations)
  {
    return configurations ? static_cast<Eigen::Index>(position_values / (3 * configurations)) : 0;
  }

  /// The float64 or the float32 field of a compact response.
  template <typename Scalar>
  static const std::vector<Scalar>& compactField(const std::vector<double>& f64, const std::vector<float>& f32)
  {
    if constexpr (std::is_same<Scalar, float>::value)
      return f32;
    else
      return f64;
  }

  ros::NodeHandle nh_;
  std::string server_;
  ros::Duration timeout_;
  ros::ServiceClient get_bodies_, set_state_, get_state_, get_mass_matrix_, get_vertex_jacobians_, backprop_,
      get_vertex_jacobians_compact_;
};

}  // namespace diff_rigid_body_ros
