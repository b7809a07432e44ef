// LocalScene's queries: each calls the SceneQueries member that the node's handler of the same
// service calls (src/node/rigid_body_server.cpp), with the GIL released, and moves the answer's
// arrays into numpy (adopt) under the response's field names (the answer's field list).
#include <optional>

#include <pybind11/stl.h>

#include "diff_rigid_body/services/bodies_answer.h"
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

// One dict entry per field of an answer's field list (scene_queries.h, bodies_answer.h), under the
// response field's name; used with `answer` and the dict `r` in scope.
#define DRB_PYTHON_FIELD(type, name) r[#name] = toPython(std::move(answer.name));

py::dict LocalScene::getBodies() const
{
  BodiesAnswer answer;
  serve("get_bodies", [&] { answer = describeBodies(queries_->scene()); });
  py::dict r;
  DRB_GetBodies_RESPONSE_FIELDS(DRB_PYTHON_FIELD)
  return r;
}

py::dict LocalScene::getMassMatrix(const std::vector<std::string>& bodies, const InputArray<double>& q,
                                   bool derivatives) const
{
  const Values<double> x = requiredQ(q, "get_mass_matrix");
  MassMatrixAnswer answer;
  serve("get_mass_matrix", [&] { queries_->massMatrices(state_, bodies, x.view(), derivatives, answer); });
  py::dict r;
  DRB_GetMassMatrix_RESPONSE_FIELDS(DRB_PYTHON_FIELD)
  return r;
}

py::dict LocalScene::getVertexJacobians(const std::string& body, const InputArray<std::uint32_t>& vertices,
                                        const InputArray<double>& q) const
{
  const Values<double> x = requiredQ(q, "get_vertex_jacobians");
  const Values<std::uint32_t> selected(vertices);
  std::vector<double> positions, jacobians;
  serve("get_vertex_jacobians",
        [&] { queries_->vertexJacobians(state_, body, selected.vector(), x.view(), positions, jacobians); });
  py::dict r;
  r["positions"] = adopt(std::move(positions));
  r["jacobians"] = adopt(std::move(jacobians));
  return r;
}

py::dict LocalScene::getVertexJacobiansCompact(const std::string& body, const InputArray<std::uint32_t>& vertices,
                                               const InputArray<double>& q, bool positions_only,
                                               bool single_precision) const
{
  const Values<double> x = requiredQ(q, "get_vertex_jacobians_compact");
  const std::vector<std::uint32_t> selected = Values<std::uint32_t>(vertices).vector();
  py::dict r;
  // Out: float for the float32 transport's fields (*_f32), else double.
  const auto answer = [&](auto out, const char* positions_field, const char* jacobians_field) {
    std::vector<decltype(out)> positions, jacobians;
    serve("get_vertex_jacobians_compact", [&] {
      queries_->vertexRotationJacobians(state_, body, selected, x.view(), positions_only, positions, jacobians);
    });
    r[positions_field] = adopt(std::move(positions));
    r[jacobians_field] = adopt(std::move(jacobians));
  };
  if (single_precision)
    answer(0.0f, "positions_f32", "rotation_jacobians_f32");
  else
    answer(0.0, "positions", "rotation_jacobians");
  return r;
}

py::dict LocalScene::backprop(const std::string& body, const InputArray<std::uint32_t>& vertices,
                              const InputArray<double>& gradients, const InputArray<double>& q) const
{
  const Values<double> x = requiredQ(q, "backprop");
  const Values<std::uint32_t> selected(vertices);
  const Values<double> dl_dp(gradients);
  std::vector<double> gradient;
  serve("backprop", [&] {
    queries_->backpropConfigurations(state_, body, selected.vector(), dl_dp.view(), x.view(), gradient);
  });
  py::dict r;
  r["gradient"] = adopt(std::move(gradient));
  return r;
}

py::dict LocalScene::inverseDynamics(const std::vector<std::string>& bodies, const InputArray<double>& q,
                                     const InputArray<double>& qdot, const InputArray<double>& qddot,
                                     bool coriolis_matrices, bool derivatives) const
{
  const Values<double> x = requiredQ(q, "inverse_dynamics"), v(qdot), a(qddot);
  InverseDynamicsAnswer answer;
  serve("inverse_dynamics", [&] {
    queries_->inverseDynamics(state_, bodies, x.view(), v.view(), a.view(), coriolis_matrices, derivatives,
                              answer);
  });
  py::dict r;
  DRB_InverseDynamics_RESPONSE_FIELDS(DRB_PYTHON_FIELD)
  return r;
}

py::dict LocalScene::forwardDynamics(const std::vector<std::string>& bodies, const InputArray<double>& q,
                                     const InputArray<double>& qdot, const InputArray<double>& tau,
                                     bool derivatives) const
{
  const Values<double> x = requiredQ(q, "forward_dynamics"), v(qdot), t(tau);
  ForwardDynamicsAnswer answer;
  serve("forward_dynamics", [&] {
    queries_->forwardDynamics(state_, bodies, x.view(), v.view(), t.view(), derivatives, answer);
  });
  py::dict r;
  DRB_ForwardDynamics_RESPONSE_FIELDS(DRB_PYTHON_FIELD)
  return r;
}

py::dict LocalScene::getFrameJacobians(const std::string& body, const std::vector<std::string>& frames,
                                       const InputArray<double>& q, const InputArray<double>& qdot,
                                       std::uint32_t reference, bool acceleration_bias) const
{
  const Values<double> x = requiredQ(q, "get_frame_jacobians"), v(qdot);
  FrameJacobianAnswer answer;
  serve("get_frame_jacobians", [&] {
    queries_->frameJacobians(state_, body, frames, x.view(), v.view(), reference, acceleration_bias, answer);
  });
  py::dict r;
  DRB_GetFrameJacobians_RESPONSE_FIELDS(DRB_PYTHON_FIELD)
  return r;
}

py::dict LocalScene::getCenterOfMass(const std::vector<std::string>& bodies, const InputArray<double>& q,
                                     const InputArray<double>& qdot, bool jacobians) const
{
  const Values<double> x = requiredQ(q, "get_center_of_mass"), v(qdot);
  CenterOfMassAnswer answer;
  serve("get_center_of_mass",
        [&] { queries_->centerOfMass(state_, bodies, x.view(), v.view(), jacobians, answer); });
  py::dict r;
  DRB_GetCenterOfMass_RESPONSE_FIELDS(DRB_PYTHON_FIELD)
  return r;
}

}  // namespace python
}  // namespace diff_rigid_body
