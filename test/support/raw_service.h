// Raw service calls of one rigid_body_server: the request goes out as built
// and the response comes back as the node sent it (success=false included).
// For what the shipped client (diff_rigid_body_ros::RigidBodyClient) cannot
// express, e.g. arrays of the wrong size, or does not expose, e.g. a field it
// drops. Everything else goes through the client.
//
// One persistent connection per service, made on first use; a transport
// failure is an exception (gtest reports it as a failure of the test).
#pragma once

#include <map>
#include <utility>
#include <stdexcept>
#include <string>

#include <ros/ros.h>

namespace drb_test
{
class RawServices
{
public:
  /// \param server  the node's resolved name, e.g. "/rigid_body_server".
  explicit RawServices(std::string server, ros::Duration timeout = ros::Duration(60.0))
    : server_(std::move(server)), timeout_(timeout)
  {
  }

  /// Calls `<server>/<service>` with `request`; returns the node's response.
  template <typename Service>
  typename Service::Response call(const std::string& service, const typename Service::Request& request = {})
  {
    const std::string name = server_ + "/" + service;
    ros::ServiceClient& client = clients_[service];
    if (!client.isValid())
    {
      if (!ros::service::waitForService(name, timeout_))
        throw std::runtime_error("service " + name + " did not appear within " + std::to_string(timeout_.toSec()) +
                                 " s");
      client = ros::NodeHandle().serviceClient<Service>(name, /*persistent=*/true);
    }
    Service srv;
    srv.request = request;
    if (!client.call(srv))
      throw std::runtime_error("call of " + name + " failed (is the node still running?)");
    return srv.response;
  }

  const std::string& server() const { return server_; }

private:
  std::string server_;
  ros::Duration timeout_;
  std::map<std::string, ros::ServiceClient> clients_;
};
}  // namespace drb_test
