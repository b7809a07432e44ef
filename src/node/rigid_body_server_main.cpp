// rigid_body_server: loads a URDF scene and serves differentiable rigid-body
// quantities. An unusable description is logged and the node exits with 1;
// it never half-starts.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <ros/package.h>
#include <ros/ros.h>

#include "diff_rigid_body/exceptions.h"
#include "rigid_body_server.h"
#include "server_helpers.h"

namespace drb = diff_rigid_body;

namespace
{
// Reads ~bodies as a list of strings, or as one string of names separated by
// commas or spaces (convenient on the roslaunch command line).
std::vector<std::string> readBodies(const ros::NodeHandle& private_nh)
{
  std::vector<std::string> bodies;
  if (private_nh.getParam("bodies", bodies))
    return bodies;
  std::string text;
  if (private_nh.getParam("bodies", text))
  {
    std::replace(text.begin(), text.end(), ',', ' ');
    std::istringstream words(text);
    for (std::string word; words >> word;)
      bodies.push_back(word);
    return bodies;
  }
  if (private_nh.hasParam("bodies"))
    throw drb::SceneDescriptionError("parameter ~bodies: must be a list of body names");
  return bodies;
}

// package:// resolution as roslib does it (rospack over ROS_PACKAGE_PATH); an unknown package
// throws, saying where it was looked for and what to check.
std::string findPackage(const std::string& package)
{
  const std::string path = ros::package::getPath(package);
  if (!path.empty())
    return path;
  const char* package_path = std::getenv("ROS_PACKAGE_PATH");
  throw std::runtime_error("no such package on ROS_PACKAGE_PATH (" +
                           std::string(package_path && *package_path ? package_path : "unset") +
                           "): check that ROS_PACKAGE_PATH lists the folder that holds the package '" + package +
                           "' (e.g. export ROS_PACKAGE_PATH=/path/to/its/parent:$ROS_PACKAGE_PATH)");
}

drb::SceneOptions readSceneOptions(const ros::NodeHandle& private_nh)
{
  drb::SceneOptions options;
  const std::string geometry = private_nh.param<std::string>("geometry", "collision");
  if (geometry == "visual")
    options.geometry = drb::GeometrySource::Visual;
  else if (geometry != "collision")
    throw drb::SceneDescriptionError("parameter ~geometry: must be 'collision' or 'visual', got '" + geometry + "'");
  double density = 0.0;
  if (private_nh.getParam("density", density))
    options.density = density;
  else if (private_nh.hasParam("density"))
    throw drb::SceneDescriptionError("parameter ~density: must be a number [kg/m^3]");
  options.bodies = readBodies(private_nh);
  options.strict_inertia = private_nh.param("strict_inertia", false);
  const std::string joints = private_nh.param<std::string>("joints", "model");
  if (joints == "free")
    options.joints = drb::JointHandling::Free;
  else if (joints != "model")
    throw drb::SceneDescriptionError("parameter ~joints: must be 'model' or 'free', got '" + joints + "'");
  options.fixed_frame = private_nh.param<std::string>("fixed_frame", "");
  if (!private_nh.getParam("floating_base", options.floating_base) && private_nh.hasParam("floating_base"))
    throw drb::SceneDescriptionError("parameter ~floating_base: must be true or false");
  options.find_package = findPackage;
  return options;
}

// ~gravity: three finite numbers [m/s^2], gamma in the fixed frame.
Eigen::Vector3d readGravity(const ros::NodeHandle& private_nh)
{
  std::vector<double> gravity;
  if (!private_nh.hasParam("gravity"))
    return drb::standardGravity();
  if (!private_nh.getParam("gravity", gravity) || gravity.size() != 3 ||
      !std::all_of(gravity.begin(), gravity.end(), [](double g) { return std::isfinite(g); }))
    throw drb::SceneDescriptionError("parameter ~gravity: must be a list of three finite numbers [m/s^2], "
                                     "e.g. [0, 0, -9.81]");
  return Eigen::Vector3d(gravity[0], gravity[1], gravity[2]);
}

drb::Scene loadScene(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh)
{
  const drb::SceneOptions options = readSceneOptions(private_nh);
  const std::string urdf_path = private_nh.param<std::string>("urdf_path", "");
  if (!urdf_path.empty())
    return drb::loadSceneFromUrdfFile(urdf_path, options);
  std::string urdf_xml;
  if (!nh.getParam("robot_description", urdf_xml))
  {
    if (nh.hasParam("robot_description"))
      throw drb::SceneDescriptionError("parameter robot_description: must be a string (URDF XML)");
    throw drb::SceneDescriptionError("no robot description: set the parameter '" +
                                     nh.resolveName("robot_description") + "' or ~urdf_path");
  }
  return drb::loadSceneFromUrdf(urdf_xml, options);
}

// The line that says the node is ready: "rigid_body_server: serving N bodies in '<fixed frame>': ...".
std::string servingSummary(const drb::Scene& scene)
{
  std::ostringstream summary;
  summary << "rigid_body_server: serving " << scene.bodies.size() << " bodies in '" << scene.fixed_frame << "':";
  for (const drb::BodyModel& body : scene.bodies)
    summary << " " << body.name << " (" << body.coordinates << " coordinates, " << body.vertexCount() << " vertices)";
  return summary.str();
}
}  // namespace

int main(int argc, char** argv)
{
  // ROS_INFO goes to stdout: line-buffered, so that a pipe or a log file (roslaunch output="log")
  // gets each line when it is written, not when the buffer fills or the node exits.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  ros::init(argc, argv, "rigid_body_server");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");

  drb::ServerSettings settings;
  const double rate = private_nh.param("publish_rate", settings.publish_rate);
  settings.publish_rate = std::isfinite(rate) ? std::clamp(rate, 0.1, 1000.0) : settings.publish_rate;
  if (settings.publish_rate != rate)
    ROS_WARN("~publish_rate %g Hz is out of range; using %g Hz", rate, settings.publish_rate);
  const int threads = std::clamp(private_nh.param("threads", 4), 1, 64);
  settings.state_file = private_nh.param<std::string>("state_file", "");
  settings.frame_prefix = private_nh.param<std::string>("frame_prefix", "");

  drb::Scene scene;
  if (!drb::node::runAtStart("cannot load the scene", [&] {
        settings.gravity = readGravity(private_nh);
        scene = loadScene(nh, private_nh);
      }))
    return 1;
  // With ~joints: model only planar joints are left unmodelled, which docs/interface.md asks to warn about;
  // with ~joints: free every 1-dof joint is, by request.
  const bool free_joints = private_nh.param<std::string>("joints", "model") == "free";
  for (const std::string& joint : scene.unmodelled_joints)
  {
    if (free_joints)
      ROS_INFO_STREAM("rigid_body_server: " << joint);
    else
      ROS_WARN_STREAM("rigid_body_server: " << joint);
  }
  for (const std::string& warning : scene.warnings)
    ROS_WARN_STREAM("rigid_body_server: " << warning);

  const std::string summary = servingSummary(scene);
  std::unique_ptr<drb::RigidBodyServer> server;
  // e.g. an unwritable ~state_file
  if (!drb::node::runAtStart("cannot start", [&] {
        server = std::make_unique<drb::RigidBodyServer>(nh, private_nh, std::move(scene), settings);
      }))
    return 1;
  // Once every service is advertised; stdout is line-buffered (main), so a pipe sees it now.
  ROS_INFO_STREAM(summary);
  ros::MultiThreadedSpinner spinner(static_cast<std::uint32_t>(threads));
  spinner.spin();
  return 0;
}
