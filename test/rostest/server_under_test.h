// Persistent service clients of the rigid_body_server under test, and small
// helpers to move between messages and Eigen.
#pragma once

#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <ros/ros.h>

#include <diff_rigid_body/Backprop.h>
#include <diff_rigid_body/BodyState.h>
#include <diff_rigid_body/GetBodies.h>
#include <diff_rigid_body/GetMassMatrix.h>
#include <diff_rigid_body/GetState.h>
#include <diff_rigid_body/GetVertexJacobians.h>
#include <diff_rigid_body/SetState.h>

#include "fixture_scene.h"

namespace drb_rostest
{
namespace drb = diff_rigid_body;

/// All six services of one server, over persistent connections (the way an
/// optimiser in a loop talks to the node).
class ServerClient
{
public:
  /// \param server  the node's name, e.g. "/rigid_body_server"; its services are "<server>/<service>".
  explicit ServerClient(const std::string& server) : server_(server)
  {
    // A persistent client connects when it is created, so wait for the
    // services first.
    for (const char* service :
         { "get_bodies", "set_state", "get_state", "get_mass_matrix", "get_vertex_jacobians", "backprop" })
      if (!ros::service::waitForService(server + "/" + service, ros::Duration(60.0)))
        throw std::runtime_error("service " + server + "/" + service + " did not appear within 60 s");
    ros::NodeHandle nh;
    get_bodies_ = nh.serviceClient<drb::GetBodies>(server + "/get_bodies", true);
    set_state_ = nh.serviceClient<drb::SetState>(server + "/set_state", true);
    get_state_ = nh.serviceClient<drb::GetState>(server + "/get_state", true);
    get_mass_matrix_ = nh.serviceClient<drb::GetMassMatrix>(server + "/get_mass_matrix", true);
    get_vertex_jacobians_ = nh.serviceClient<drb::GetVertexJacobians>(server + "/get_vertex_jacobians", true);
    backprop_ = nh.serviceClient<drb::Backprop>(server + "/backprop", true);
  }

  const std::string& name() const { return server_; }

  drb::GetBodies::Response getBodies() { return call<drb::GetBodies>(get_bodies_, {}); }

  drb::SetState::Response setState(const std::vector<drb::BodyState>& states)
  {
    drb::SetState::Request request;
    request.states = states;
    return call<drb::SetState>(set_state_, request);
  }

  drb::GetState::Response getState(const std::vector<std::string>& bodies = {})
  {
    drb::GetState::Request request;
    request.bodies = bodies;
    return call<drb::GetState>(get_state_, request);
  }

  drb::GetMassMatrix::Response getMassMatrix(const std::vector<std::string>& bodies, const std::vector<double>& q,
                                             bool derivatives)
  {
    drb::GetMassMatrix::Request request;
    request.bodies = bodies;
    request.q = q;
    request.derivatives = derivatives;
    return call<drb::GetMassMatrix>(get_mass_matrix_, request);
  }

  drb::GetVertexJacobians::Response getVertexJacobians(const std::string& body, const std::vector<double>& q = {},
                                                       const std::vector<std::uint32_t>& vertices = {})
  {
    drb::GetVertexJacobians::Request request;
    request.body = body;
    request.q = q;
    request.vertices = vertices;
    return call<drb::GetVertexJacobians>(get_vertex_jacobians_, request);
  }

  drb::Backprop::Response backprop(const std::string& body, const std::vector<double>& gradients,
                                   const std::vector<double>& q = {}, const std::vector<std::uint32_t>& vertices = {})
  {
    drb::Backprop::Request request;
    request.body = body;
    request.gradients = gradients;
    request.q = q;
    request.vertices = vertices;
    return call<drb::Backprop>(backprop_, request);
  }

private:
  /// Calls the service; a transport failure (node gone, connection dropped)
  /// is an exception, which gtest reports as a failure of the test.
  template <typename Service>
  typename Service::Response call(ros::ServiceClient& client, const typename Service::Request& request)
  {
    Service service;
    service.request = request;
    if (!client.call(service))
      throw std::runtime_error("call of " + client.getService() + " failed (is the node still running?)");
    return service.response;
  }

  std::string server_;
  ros::ServiceClient get_bodies_, set_state_, get_state_, get_mass_matrix_, get_vertex_jacobians_, backprop_;
};

/// The server under test: private parameter ~server of the test node
/// (default "/rigid_body_server"), connected on first use.
ServerClient& server();

// ---------------------------------------------------------------------------
// Conversions.

inline drb::BodyState bodyState(const std::string& name, const Vector6d& q)
{
  drb::BodyState state;
  state.name = name;
  for (int i = 0; i < 6; ++i)
    state.q[i] = q[i];
  return state;
}

inline Vector6d toVector(const drb::BodyState& state)
{
  return Eigen::Map<const Vector6d>(state.q.data());
}

inline std::vector<double> toStdVector(const Vector6d& q)
{
  return std::vector<double>(q.data(), q.data() + 6);
}

/// Same names, and q equal bit for bit (memcmp: NaN payloads and -0 count).
inline bool bitwiseEqual(const std::vector<drb::BodyState>& a, const std::vector<drb::BodyState>& b)
{
  if (a.size() != b.size())
    return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].name != b[i].name || std::memcmp(a[i].q.data(), b[i].q.data(), sizeof(double) * 6) != 0)
      return false;
  return true;
}

inline std::string describe(const std::vector<drb::BodyState>& states)
{
  std::ostringstream out;
  out.precision(17);
  for (const drb::BodyState& s : states)
  {
    out << s.name << " [";
    for (double v : s.q)
      out << " " << v;
    out << " ]; ";
  }
  return out.str();
}

/// Vertex i's position (3 per vertex) from a get_vertex_jacobians answer.
inline Eigen::Vector3d positionOf(const drb::GetVertexJacobians::Response& response, std::size_t i)
{
  return Eigen::Map<const Eigen::Vector3d>(response.positions.data() + 3 * i);
}

/// Vertex i's 3x6 Jacobian (18 per vertex, row-major).
inline Matrix36d jacobianOf(const drb::GetVertexJacobians::Response& response, std::size_t i)
{
  return Eigen::Map<const Eigen::Matrix<double, 3, 6, Eigen::RowMajor>>(response.jacobians.data() + 18 * i);
}

/// Matrix `index` (36 row-major values each) of a flat array.
inline Matrix6d matrixAt(const std::vector<double>& values, std::size_t index)
{
  return Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(values.data() + 36 * index);
}

/// True if `text` contains `fragment`, ignoring case.
inline bool containsIgnoringCase(std::string text, std::string fragment)
{
  for (char& c : text)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (char& c : fragment)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text.find(fragment) != std::string::npos;
}

}  // namespace drb_rostest
