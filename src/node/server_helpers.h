// Helpers of rigid_body_server.cpp: message conversions and the service
// wrappers that turn core errors into `success=false, message=...`.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <boost/function.hpp>
#include <geometry_msgs/Transform.h>
#include <ros/ros.h>

#include "bounded_request.h"
#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace node
{
/// `pose` as a tf transform: its translation [m], and its rotation as a unit
/// quaternion (x, y, z, w).
inline void setTransform(const Eigen::Isometry3d& pose, geometry_msgs::Transform& transform)
{
  transform.translation.x = pose.translation().x();
  transform.translation.y = pose.translation().y();
  transform.translation.z = pose.translation().z();
  const Eigen::Quaterniond rotation(pose.linear());
  transform.rotation.x = rotation.x();
  transform.rotation.y = rotation.y();
  transform.rotation.z = rotation.z();
  transform.rotation.w = rotation.w();
}

/// Runs `work`; a core error becomes success=false with its message, so that
/// the client receives it and nothing else happens. Returns true for roscpp.
template <typename Response, typename Work>
bool serve(Response& response, const char* service, Work&& work)
{
  try
  {
    work();
    response.success = true;
    response.message = "";
  }
  catch (const Error& e)
  {
    response = Response();
    response.success = false;
    response.message = e.what();
    ROS_DEBUG_STREAM(service << ": refused: " << e.what());
  }
  catch (const std::exception& e)  // e.g. std::bad_alloc: report, keep serving
  {
    response = Response();
    response.success = false;
    response.message = std::string("internal error: ") + e.what();
    ROS_ERROR_STREAM(service << ": " << response.message);
  }
  return true;
}

/// Appends `matrix` row-major to `out`.
template <typename Matrix>
void appendMatrix(const Matrix& matrix, std::vector<double>& out)
{
  for (Eigen::Index r = 0; r < matrix.rows(); ++r)
    for (Eigen::Index c = 0; c < matrix.cols(); ++c)
      out.push_back(matrix(r, c));
}

/// Advertises `handler` for the service Srv with bounded request decoding
/// (bounded_request.h): a request refused there gets success=false and the
/// refusal, and never reaches the handler.
template <typename Srv, typename Server>
ros::ServiceServer advertiseBounded(ros::NodeHandle& nh, const std::string& name,
                                    bool (Server::*handler)(typename Srv::Request&, typename Srv::Response&),
                                    Server* server)
{
  using Bounded = BoundedRequest<typename Srv::Request>;
  using Response = typename Srv::Response;
  const boost::function<bool(Bounded&, Response&)> callback = [server, handler, name](Bounded& bounded,
                                                                                      Response& response) {
    if (bounded.refusal.empty())
      return (server->*handler)(bounded.request, response);
    response = Response();
    response.success = false;
    response.message = bounded.refusal;
    ROS_DEBUG_STREAM(name << ": refused: " << bounded.refusal);
    return true;
  };
  return nh.advertiseService<Bounded, Response>(name, callback);
}
}  // namespace node
}  // namespace diff_rigid_body
