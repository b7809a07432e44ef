// How diff_rigid_body_ros::RigidBodyClient and RigidBodyPool read names: the node of a pool
// entry (a namespace or the node's own name) and what to say when no node answers to a name.
// The counterpart of src/diff_rigid_body/client_names.py.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include <ros/master.h>
#include <ros/service.h>

namespace diff_rigid_body_ros
{
namespace detail
{
/// The node of pool entry `entry`: `entry` itself when its last name is `server` (a node name,
/// e.g. "/pool1/rigid_body_server"), else "<entry>/<server>" (a namespace, e.g. "/pool1").
inline std::string poolNodeName(std::string entry, const std::string& server)
{
  while (!entry.empty() && entry.back() == '/')
    entry.pop_back();
  const std::size_t slash = entry.rfind('/');
  const std::string last = slash == std::string::npos ? entry : entry.substr(slash + 1);
  return last == server ? entry : entry + "/" + server;
}

/// Why `service` of `node` was not advertised within `timeout` [s], and what to check: whether
/// a node of that name runs at all, and a rigid_body_server below it (a namespace given for a node).
inline std::string missingNodeMessage(const std::string& node, const std::string& service, double timeout)
{
  std::vector<std::string> nodes;
  bool running = false;
  if (ros::master::getNodes(nodes))
    for (const std::string& name : nodes)
      running = running || name == node;
  std::ostringstream text;
  if (running)
    text << "node " << node << " is running but did not advertise " << service << " within " << timeout
         << " s (is it a rigid_body_server? still loading its scene?)";
  else
    text << "no node at " << node << " (is it running? rosnode list): " << service << " was not advertised within "
         << timeout << " s";
  const std::string below = node + "/rigid_body_server";
  if (ros::service::exists(below + "/get_bodies", false))
    text << "; a client takes the node's name, and below " << node << " there is " << below;
  return text.str();
}
}  // namespace detail
}  // namespace diff_rigid_body_ros
