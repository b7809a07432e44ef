// The in-process scene of diff_rigid_body._local: the node's core
// (SceneQueries) loaded from a URDF, answering the node's state-free
// services. Each method takes the service's request fields and returns its
// response fields as a dict of numpy arrays (and lists of names), from the
// same SceneQueries member the node's handler calls, so the values are the
// node's bit for bit.
//
// A local scene has no state: every `q` must hold K x D values (empty q is
// refused). Core refusals are thrown as Refusal {service, message} with the
// node's message; the module raises them as diff_rigid_body's
// DiffRigidBodyError. The GIL is released while the core runs, and several
// threads may call one scene at once (SceneQueries keeps one workspace per
// thread).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "local_arrays.h"

namespace diff_rigid_body
{
namespace python
{
/// A refused request: `service` is the node's service name (or "load").
struct Refusal
{
  std::string service;
  std::string message;
};

/// The node's load options (docs/interface.md, Parameters), as keyword arguments take them.
struct LoadOptions
{
  std::string geometry = "collision";  ///< 'collision' or 'visual'
  std::vector<std::string> bodies;     ///< empty = all
  std::optional<double> density;       ///< [kg/m^3]
  std::string joints = "model";        ///< 'model' or 'free'
  bool strict_inertia = false;
  bool floating_base = false;
  std::string fixed_frame;             ///< empty = the root link ("world" with floating_base)
  std::vector<double> gravity = { 0.0, 0.0, -9.81 };  ///< [m/s^2] in the fixed frame
  py::object find_package;             ///< package name -> folder ("" when unknown), or None
};

class LocalScene
{
public:
  /// Loads `urdf` (XML, or a file path when `is_path`); throws Refusal
  /// {"load", ...} for a description the node would refuse, and
  /// py::value_error for an option of the wrong form.
  LocalScene(const std::string& urdf, bool is_path, const LoadOptions& options);

  /// Unmodelled joints, then the load warnings (the node logs both).
  const std::vector<std::string>& warnings() const { return warnings_; }

  const SceneQueries& queries() const { return *queries_; }
  /// The URDF state: never read for a request with q (kept so that no query can meet an empty state).
  const SceneState& state() const { return state_; }

private:
  std::unique_ptr<SceneQueries> queries_;
  SceneState state_;
  std::vector<std::string> warnings_;
};

/// Binds, as methods of `scene` named after their services, the services a core member answers
/// (DRB_CORE_SERVICES, from each .srv's declaration): the request fields in the .srv's order as
/// keyword arguments (float64[] and uint32[] as numpy arrays; each defaults as an unset ROS request
/// field: empty, 0 or false, and an empty q is refused), the response fields as the dict's entries.
void bindCoreServices(py::class_<LocalScene>& scene);

}  // namespace python
}  // namespace diff_rigid_body
