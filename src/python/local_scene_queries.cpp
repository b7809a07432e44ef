// LocalScene's queries: each calls the SceneQueries member that the node's handler of the same
// service calls (src/node/rigid_body_server.cpp), with the GIL released, and moves the answer's
// arrays into numpy (adopt) under the response's field names (the answer's field list). The
// services a core member answers are bound from their declarations (DRB_CORE_SERVICES).
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>

#include <pybind11/stl.h>

#include "diff_rigid_body/exceptions.h"
#include "local_scene.h"

namespace diff_rigid_body
{
namespace python
{
namespace
{
/// Runs `work` without the GIL; a core refusal becomes Refusal {service, its message}.
template <typename Work>
void serve(const char* service, Work&& work)
{
  std::optional<Refusal> refusal;
  {
    py::gil_scoped_release release;
    try
    {
      work();
    }
    catch (const Error& e)
    {
      refusal = Refusal{ service, e.what() };
    }
  }
  if (refusal)
    throw *refusal;
}

/// q's values; a local scene has no current state for an empty q to stand for.
Values<double> requiredQ(const InputArray<double>& q, const char* service)
{
  if (q.size() == 0)
    throw Refusal{ service, "q: required: a local scene has no state (give K configurations, K >= 1)" };
  return Values<double>(q);
}

/// A request field of C++ type T as the module takes it (Input), holds it while the core runs
/// (hold, with the GIL) and hands it to the core member (pass): as pybind converts it, but for
/// float64[] (read in place when C-contiguous; q is required) and uint32[] (numpy arrays).
template <typename T>
struct LocalField
{
  using Input = T;
  static const T& hold(const T& value, const char*, const char*) { return value; }
  static const T& pass(const T& value) { return value; }
};
template <>
struct LocalField<std::vector<double>>
{
  using Input = InputArray<double>;
  static Values<double> hold(const Input& values, const char* field, const char* service)
  {
    return std::strcmp(field, "q") == 0 ? requiredQ(values, service) : Values<double>(values);
  }
  static DoubleView pass(const Values<double>& values) { return values.view(); }
};
template <>
struct LocalField<std::vector<std::uint32_t>>
{
  using Input = InputArray<std::uint32_t>;
  static std::vector<std::uint32_t> hold(const Input& values, const char*, const char*)
  {
    return Values<std::uint32_t>(values).vector();
  }
  static const std::vector<std::uint32_t>& pass(const std::vector<std::uint32_t>& values) { return values; }
};

template <>
struct LocalField<std::uint8_t>
{
  using Input = std::int64_t;  // any Python int that fits: out of 0..255 is refused, not a TypeError
  static std::uint8_t hold(Input value, const char* field, const char* service)
  {
    if (value < 0 || value > 255)
      throw Refusal{ service, std::string(field) + ": " + std::to_string(value) + " is not a uint8 (0..255)" };
    return static_cast<std::uint8_t>(value);
  }
  static std::uint8_t pass(std::uint8_t value) { return value; }
};

/// The keyword argument of a request field, defaulting as a ROS request leaves a field unset:
/// empty arrays and names, 0, false (an empty q is then refused: LocalField, requiredQ).
template <typename T>
py::arg_v keyword(const char* name, const T*)
{
  return py::arg_v(name, typename LocalField<T>::Input{});
}

// A response field as Python: numeric vectors handed to numpy (adopt), names as a list, scalars.
template <typename T>
py::object toPython(std::vector<T>&& values)
{
  return adopt(std::move(values));
}
py::object toPython(std::vector<std::string>&& names)
{
  return py::cast(names);
}
py::object toPython(std::string&& text)
{
  return py::str(text);
}
py::object toPython(std::uint32_t value)
{
  return py::int_(value);
}
}  // namespace

// One dict entry per field of an answer's field list (scene_queries.h), under the
// response field's name; used with `answer` and the dict `r` in scope.
#define DRB_PYTHON_FIELD(type, name) r[#name] = toPython(std::move(answer.name));

// One method per row of DRB_CORE_SERVICES: the request fields as arguments (LocalField), the core
// member on this scene's URDF state, the answer's fields as the dict.
#define DRB_LOCAL_INPUT(type, name) , const LocalField<type>::Input& name
#define DRB_LOCAL_HOLD(type, name) const auto& name##_held = LocalField<type>::hold(name, #name, service);
#define DRB_LOCAL_PASS(type, name) , LocalField<type>::pass(name##_held)
#define DRB_LOCAL_KEYWORD(type, name) , keyword(#name, static_cast<const type*>(nullptr))
#define DRB_BIND_CORE(Type, name, handler, member, Answer)                                                             \
  scene.def(                                                                                                           \
      #name,                                                                                                           \
      [](const LocalScene& self DRB_##Type##_REQUEST_FIELDS(DRB_LOCAL_INPUT)) {                                        \
        const char* service = #name;                                                                                   \
        DRB_##Type##_REQUEST_FIELDS(DRB_LOCAL_HOLD)                                                                    \
        Answer answer;                                                                                                 \
        serve(service, [&] {                                                                                           \
          self.queries().member(self.state() DRB_##Type##_REQUEST_FIELDS(DRB_LOCAL_PASS), answer);                     \
        });                                                                                                            \
        py::dict r;                                                                                                    \
        DRB_##Type##_RESPONSE_FIELDS(DRB_PYTHON_FIELD)                                                                 \
        return r;                                                                                                      \
      } DRB_##Type##_REQUEST_FIELDS(DRB_LOCAL_KEYWORD));

void bindCoreServices(py::class_<LocalScene>& scene)
{
  DRB_CORE_SERVICES(DRB_BIND_CORE)
}
#undef DRB_BIND_CORE
#undef DRB_LOCAL_KEYWORD
#undef DRB_LOCAL_PASS
#undef DRB_LOCAL_HOLD
#undef DRB_LOCAL_INPUT
#undef DRB_PYTHON_FIELD

}  // namespace python
}  // namespace diff_rigid_body
