// Helpers of rigid_body_server.cpp: message conversions and the service
// wrappers that turn core errors into `success=false, message=...`.
#pragma once

#include <cstdlib>
#include <exception>
#include <string>
#include <typeinfo>
#include <vector>

#include <cxxabi.h>

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

/// The message for an exception caught at a boundary of the node (`where`:
/// a service, topic, timer or the load): a core Error's own message, which
/// names what was wrong; any other std::exception, which only a bug of ours
/// can raise, as "internal error in <where>: <what> (<type>)".
inline std::string failureMessage(const std::exception& error, const std::string& where)
{
  if (dynamic_cast<const Error*>(&error))
    return error.what();
  int status = 0;
  char* type = abi::__cxa_demangle(typeid(error).name(), nullptr, nullptr, &status);
  const std::string message = "internal error in " + where + ": " + error.what() + " (" +
                              (status == 0 && type ? type : typeid(error).name()) + ")";
  std::free(type);
  return message;
}

/// Frame names as tf knows them (with ~frame_prefix) to the scene's URDF
/// names: `prefix` is removed from the start of each name that has it.
inline void removeFramePrefix(const std::string& prefix, std::vector<std::string>& names)
{
  if (prefix.empty())
    return;
  for (std::string& name : names)
    if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0)
      name.erase(0, prefix.size());
}

/// Runs `work`; any exception becomes success=false with failureMessage, so
/// that the client receives it, nothing changed, and the node keeps serving.
/// Returns true for roscpp.
template <typename Response, typename Work>
bool serve(Response& response, const char* service, Work&& work)
{
  try
  {
    work();
    response.success = true;
    response.message = "";
  }
  catch (const std::exception& e)
  {
    response = Response();
    response.success = false;
    response.message = failureMessage(e, service);
    if (dynamic_cast<const Error*>(&e))
      ROS_DEBUG_STREAM(service << ": refused: " << response.message);
    else
      ROS_ERROR_STREAM(service << ": " << response.message);
  }
  return true;
}

/// serve() for a batched query: `query(answer)` fills a fresh Answer of
/// scene_queries.h, which is then moved into the response field by field
/// (Answer::moveInto, from the answer's one field list).
template <typename Answer, typename Response, typename Query>
bool serveAnswer(Response& response, const char* service, Query&& query)
{
  return serve(response, service, [&] {
    Answer answer;
    query(answer);
    answer.moveInto(response);
  });
}

/// Runs a topic or timer callback's `work`. Any exception is caught here, so
/// that none reaches roscpp (which would end the node): it becomes the
/// returned message (failureMessage, "" when `work` returned), which the
/// caller logs, e.g. as "message dropped".
template <typename Work>
std::string guardCallback(const char* where, Work&& work)
{
  try
  {
    work();
    return std::string();
  }
  catch (const std::exception& e)
  {
    return failureMessage(e, where);
  }
}

/// Runs the node's start-up `work` (loading the scene, starting the server).
/// Returns false after logging "rigid_body_server: <what>: <failureMessage>"
/// as FATAL for any exception, so that main exits 1 and never aborts.
template <typename Work>
bool runAtStart(const std::string& what, Work&& work)
{
  const std::string failure = guardCallback(what.c_str(), std::forward<Work>(work));
  if (failure.empty())
    return true;
  ROS_FATAL_STREAM("rigid_body_server: " << what << ": " << failure);
  return false;
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
