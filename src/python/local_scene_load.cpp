// LocalScene's construction: the node's load options (rigid_body_server_main.cpp reads the same
// ones from ROS parameters) into SceneOptions, then the core's loader.
#include <cmath>

#include "diff_rigid_body/exceptions.h"
#include "local_scene.h"

namespace diff_rigid_body
{
namespace python
{
namespace
{
SceneOptions sceneOptions(const LoadOptions& options)
{
  SceneOptions scene;
  if (options.geometry == "visual")
    scene.geometry = GeometrySource::Visual;
  else if (options.geometry != "collision")
    throw py::value_error("geometry: must be 'collision' or 'visual', got '" + options.geometry + "'");
  if (options.joints == "free")
    scene.joints = JointHandling::Free;
  else if (options.joints != "model")
    throw py::value_error("joints: must be 'model' or 'free', got '" + options.joints + "'");
  scene.density = options.density;
  scene.bodies = options.bodies;
  scene.strict_inertia = options.strict_inertia;
  scene.floating_base = options.floating_base;
  scene.fixed_frame = options.fixed_frame;
  if (!options.find_package.is_none())
  {
    // Called by the loader with the GIL held (loading keeps it); a failing resolver means "unknown".
    const py::object resolver = options.find_package;
    scene.find_package = [resolver](const std::string& package) {
      try
      {
        return resolver(package).cast<std::string>();
      }
      catch (const py::error_already_set&)
      {
        return std::string();
      }
    };
  }
  return scene;
}

// gamma [m/s^2]: three finite numbers, as ~gravity.
Eigen::Vector3d gravityOf(const std::vector<double>& gravity)
{
  if (gravity.size() != 3 || !std::isfinite(gravity[0]) || !std::isfinite(gravity[1]) || !std::isfinite(gravity[2]))
    throw py::value_error("gravity: must be three finite numbers [m/s^2], e.g. [0, 0, -9.81]");
  return Eigen::Vector3d(gravity[0], gravity[1], gravity[2]);
}
}  // namespace

LocalScene::LocalScene(const std::string& urdf, bool is_path, const LoadOptions& options)
{
  const Eigen::Vector3d gravity = gravityOf(options.gravity);
  SceneOptions scene_options = sceneOptions(options);
  try
  {
    Scene scene = is_path ? loadSceneFromUrdfFile(urdf, scene_options) : loadSceneFromUrdf(urdf, scene_options);
    warnings_ = scene.unmodelled_joints;
    warnings_.insert(warnings_.end(), scene.warnings.begin(), scene.warnings.end());
    queries_ = std::make_unique<SceneQueries>(std::move(scene), gravity);
  }
  catch (const Error& e)
  {
    throw Refusal{ "load", e.what() };
  }
  state_ = queries_->initialState();
}

}  // namespace python
}  // namespace diff_rigid_body
