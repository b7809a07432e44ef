// LocalScene's queries: each calls the SceneQueries member that the node's handler of the same
// service calls (src/node/rigid_body_server.cpp), with the GIL released, and moves the answer's
// arrays into numpy (adopt) under the response's field names.
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
}  // namespace

py::dict LocalScene::getBodies() const
{
  BodiesAnswer answer;
  serve("get_bodies", [&] { answer = describeBodies(queries_->scene()); });
  py::dict r;
  r["fixed_frame"] = answer.fixed_frame;
  r["names"] = answer.names;
  r["masses"] = adopt(std::move(answer.masses));
  r["inertias"] = adopt(std::move(answer.inertias));
  r["com_offsets"] = adopt(std::move(answer.com_offsets));
  r["vertex_counts"] = adopt(std::move(answer.vertex_counts));
  r["dofs"] = adopt(std::move(answer.dofs));
  r["joint_names"] = answer.joint_names;
  r["joint_counts"] = adopt(std::move(answer.joint_counts));
  r["joint_lower"] = adopt(std::move(answer.joint_lower));
  r["joint_upper"] = adopt(std::move(answer.joint_upper));
  r["link_names"] = answer.link_names;
  r["link_counts"] = adopt(std::move(answer.link_counts));
  r["link_vertex_counts"] = adopt(std::move(answer.link_vertex_counts));
  r["link_masses"] = adopt(std::move(answer.link_masses));
  r["link_inertias"] = adopt(std::move(answer.link_inertias));
  r["link_com_offsets"] = adopt(std::move(answer.link_com_offsets));
  return r;
}

py::dict LocalScene::getMassMatrix(const std::vector<std::string>& bodies, const InputArray<double>& q,
                                   bool derivatives) const
{
  const Values<double> x = requiredQ(q, "get_mass_matrix");
  MassMatrixAnswer answer;
  serve("get_mass_matrix", [&] { queries_->massMatrices(state_, bodies, x.view(), derivatives, answer); });
  py::dict r;
  r["bodies"] = answer.bodies;
  r["dofs"] = adopt(std::move(answer.dofs));
  r["mass_matrices"] = adopt(std::move(answer.mass_matrices));
  r["derivatives"] = adopt(std::move(answer.derivatives));
  r["cos_theta"] = adopt(std::move(answer.cos_theta));
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
  const Values<std::uint32_t> selected(vertices);
  py::dict r;
  if (single_precision)
  {
    std::vector<float> positions, jacobians;
    serve("get_vertex_jacobians_compact", [&] {
      queries_->vertexRotationJacobians(state_, body, selected.vector(), x.view(), positions_only, positions,
                                        jacobians);
    });
    r["positions_f32"] = adopt(std::move(positions));
    r["rotation_jacobians_f32"] = adopt(std::move(jacobians));
    return r;
  }
  std::vector<double> positions, jacobians;
  serve("get_vertex_jacobians_compact", [&] {
    queries_->vertexRotationJacobians(state_, body, selected.vector(), x.view(), positions_only, positions,
                                      jacobians);
  });
  r["positions"] = adopt(std::move(positions));
  r["rotation_jacobians"] = adopt(std::move(jacobians));
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
  r["bodies"] = answer.bodies;
  r["dofs"] = adopt(std::move(answer.dofs));
  r["tau"] = adopt(std::move(answer.tau));
  r["velocity_terms"] = adopt(std::move(answer.velocity_terms));
  r["gravity_terms"] = adopt(std::move(answer.gravity_terms));
  r["coriolis_matrices"] = adopt(std::move(answer.coriolis_matrices));
  r["dtau_dq"] = adopt(std::move(answer.dtau_dq));
  r["dtau_dqdot"] = adopt(std::move(answer.dtau_dqdot));
  r["cos_theta"] = adopt(std::move(answer.cos_theta));
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
  r["bodies"] = answer.bodies;
  r["dofs"] = adopt(std::move(answer.dofs));
  r["qddot"] = adopt(std::move(answer.qddot));
  r["dqddot_dq"] = adopt(std::move(answer.dqddot_dq));
  r["dqddot_dqdot"] = adopt(std::move(answer.dqddot_dqdot));
  r["dqddot_dtau"] = adopt(std::move(answer.dqddot_dtau));
  r["cos_theta"] = adopt(std::move(answer.cos_theta));
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
  r["frames"] = answer.frames;
  r["dofs"] = answer.dofs;
  r["poses"] = adopt(std::move(answer.poses));
  r["jacobians"] = adopt(std::move(answer.jacobians));
  r["acceleration_bias"] = adopt(std::move(answer.acceleration_bias));
  r["cos_theta"] = adopt(std::move(answer.cos_theta));
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
  r["bodies"] = answer.bodies;
  r["dofs"] = adopt(std::move(answer.dofs));
  r["masses"] = adopt(std::move(answer.masses));
  r["com"] = adopt(std::move(answer.com));
  r["jacobians"] = adopt(std::move(answer.jacobians));
  r["acceleration_bias"] = adopt(std::move(answer.acceleration_bias));
  r["cos_theta"] = adopt(std::move(answer.cos_theta));
  return r;
}

}  // namespace python
}  // namespace diff_rigid_body
