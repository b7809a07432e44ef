// diff_rigid_body._local: the node's core in the caller's Python process (docs/interface.md,
// "In process"). diff_rigid_body.local.LocalScene is its Python face; this module's Scene takes
// each state-free service's request fields by name and returns its response fields as a dict.
// A Refusal is raised as diff_rigid_body.client_types.DiffRigidBodyError(service, message).
#include <string>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "local_scene.h"

namespace py = pybind11;
using diff_rigid_body::python::InputArray;
using diff_rigid_body::python::LoadOptions;
using diff_rigid_body::python::LocalScene;
using diff_rigid_body::python::Refusal;

namespace
{
LocalScene* load(const std::string& urdf, bool is_path, const std::string& geometry,
                 const std::vector<std::string>& bodies, std::optional<double> density, const std::string& joints,
                 bool strict_inertia, bool floating_base, const std::string& fixed_frame,
                 const std::vector<double>& gravity, py::object find_package)
{
  LoadOptions options;
  options.geometry = geometry;
  options.bodies = bodies;
  options.density = density;
  options.joints = joints;
  options.strict_inertia = strict_inertia;
  options.floating_base = floating_base;
  options.fixed_frame = fixed_frame;
  options.gravity = gravity;
  options.find_package = std::move(find_package);
  return new LocalScene(urdf, is_path, options);
}

void registerRefusal()
{
  // A new reference kept for the interpreter's life (the translator may run at any time).
  static PyObject* error_type =
      py::object(py::module_::import("diff_rigid_body.client_types").attr("DiffRigidBodyError")).release().ptr();
  py::register_exception_translator([](std::exception_ptr raised) {
    try
    {
      if (raised)
        std::rethrow_exception(raised);
    }
    catch (const Refusal& refusal)
    {
      py::object error = py::reinterpret_borrow<py::object>(error_type)(refusal.service, refusal.message);
      PyErr_SetObject(error_type, error.ptr());
    }
  });
}
}  // namespace

PYBIND11_MODULE(_local, m)
{
  m.doc() = "The diff_rigid_body core in process; use diff_rigid_body.LocalScene.";
  registerRefusal();
  using namespace pybind11::literals;
  // Where the core reads a float64 input: the array's own buffer when it is C-contiguous float64.
  m.def("buffer_address", [](const InputArray<double>& values) {
    return reinterpret_cast<std::uintptr_t>(diff_rigid_body::python::Values<double>(values).data);
  }, "values"_a);
  py::class_<LocalScene> scene(m, "Scene");
  scene
      .def(py::init(&load), "urdf"_a, "is_path"_a, "geometry"_a = "collision", "bodies"_a = std::vector<std::string>(),
           "density"_a = py::none(), "joints"_a = "model", "strict_inertia"_a = false, "floating_base"_a = false,
           "fixed_frame"_a = "", "gravity"_a = std::vector<double>{ 0.0, 0.0, -9.81 }, "find_package"_a = py::none())
      .def_property_readonly("warnings", &LocalScene::warnings);
  diff_rigid_body::python::bindCoreServices(scene);
  // The services a Scene answers: the node's state-free ones.
#define DRB_SERVICE_NAME(Type, name, handler, member, Answer) #name,
  m.attr("SERVICES") = py::tuple(py::cast(std::vector<std::string>{ DRB_CORE_SERVICES(DRB_SERVICE_NAME) }));
#undef DRB_SERVICE_NAME
}
