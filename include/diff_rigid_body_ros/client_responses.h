// Responses of rigid_body_server's services as the client types of
// client_types.h (used by rigid_body_client.h).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include <diff_rigid_body/Backprop.h>
#include <diff_rigid_body/ForwardDynamics.h>
#include <diff_rigid_body/GetBodies.h>
#include <diff_rigid_body/GetMassMatrix.h>
#include <diff_rigid_body/GetVertexJacobians.h>
#include <diff_rigid_body/GetVertexJacobiansCompact.h>
#include <diff_rigid_body/InverseDynamics.h>

#include "diff_rigid_body_ros/client_arrays.h"
#include "diff_rigid_body_ros/client_types.h"

namespace diff_rigid_body_ros
{
/// get_bodies: the flattened per-joint and per-link fields cut per body.
inline Bodies toBodies(const diff_rigid_body::GetBodies::Response& r)
{
  using RowMajor3d = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  Bodies out;
  out.fixed_frame = r.fixed_frame;
  out.names = r.names;
  out.masses = r.masses;
  out.vertex_counts = r.vertex_counts;
  out.dofs = r.dofs;
  for (std::size_t i = 0; i < out.names.size(); ++i)
  {
    out.inertias.push_back(Eigen::Map<const RowMajor3d>(r.inertias.data() + 9 * i));
    out.com_offsets.push_back(Eigen::Map<const Eigen::Vector3d>(r.com_offsets.data() + 3 * i));
  }
  std::size_t joint = 0;
  for (std::uint32_t count : r.joint_counts)
  {
    out.joint_names.emplace_back(r.joint_names.begin() + joint, r.joint_names.begin() + joint + count);
    out.joint_lower.emplace_back(r.joint_lower.begin() + joint, r.joint_lower.begin() + joint + count);
    out.joint_upper.emplace_back(r.joint_upper.begin() + joint, r.joint_upper.begin() + joint + count);
    joint += count;
  }
  std::size_t link = 0;
  for (std::uint32_t count : r.link_counts)
  {
    std::vector<Link> links;
    std::uint32_t first_vertex = 0;
    for (std::uint32_t k = 0; k < count; ++k, ++link)
    {
      Link l;
      l.name = r.link_names[link];
      l.mass = r.link_masses[link];
      l.inertia = Eigen::Map<const RowMajor3d>(r.link_inertias.data() + 9 * link);
      l.com_offset = Eigen::Map<const Eigen::Vector3d>(r.link_com_offsets.data() + 3 * link);
      l.first_vertex = first_vertex;
      l.vertex_count = r.link_vertex_counts[link];
      first_vertex += l.vertex_count;
      links.push_back(std::move(l));
    }
    out.links.push_back(std::move(links));
  }
  return out;
}

/// get_mass_matrix: matrix m = k n + i is d_i x d_i (d_i = dofs[i]), its
/// dM/dx_j the d_i matrices that follow in `derivatives`.
inline MassMatrices toMassMatrices(const diff_rigid_body::GetMassMatrix::Response& r, bool derivatives)
{
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  MassMatrices out;
  out.bodies = r.bodies;
  out.dofs = r.dofs;
  const std::size_t count = r.cos_theta.size(), n = out.bodies.size();
  out.configurations = n == 0 ? 0 : count / n;
  std::size_t at = 0, at_derivatives = 0;
  for (std::size_t m = 0; m < count; ++m)
  {
    const Eigen::Index d = out.dofs.at(m % n);
    out.M.push_back(Eigen::Map<const RowMajorMatrix>(r.mass_matrices.data() + at, d, d));
    at += d * d;
    if (!derivatives)
      continue;
    out.dM.emplace_back();
    for (Eigen::Index j = 0; j < d; ++j, at_derivatives += d * d)
      out.dM.back().push_back(Eigen::Map<const RowMajorMatrix>(r.derivatives.data() + at_derivatives, d, d));
  }
  out.cos_theta = r.cos_theta;
  return out;
}

/// A dynamics response field cut per entry m = k n + i (body i = m % n): d_i values (vectors) or
/// d_i^2 row-major values (matrices) each. Empty when the field is (not asked for).
inline std::vector<Eigen::VectorXd> perEntryVectors(const std::vector<double>& values,
                                                    const std::vector<std::uint32_t>& dofs, std::size_t entries)
{
  std::vector<Eigen::VectorXd> out;
  for (std::size_t m = 0, at = 0; m < entries && !values.empty(); at += dofs[m % dofs.size()], ++m)
    out.push_back(Eigen::Map<const Eigen::VectorXd>(values.data() + at, dofs[m % dofs.size()]));
  return out;
}
inline std::vector<Eigen::MatrixXd> perEntryMatrices(const std::vector<double>& values,
                                                     const std::vector<std::uint32_t>& dofs, std::size_t entries)
{
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<Eigen::MatrixXd> out;
  for (std::size_t m = 0, at = 0; m < entries && !values.empty(); ++m)
  {
    const Eigen::Index d = dofs[m % dofs.size()];
    out.push_back(Eigen::Map<const RowMajorMatrix>(values.data() + at, d, d));
    at += d * d;
  }
  return out;
}

/// A dynamics response split per entry (configuration k, body i; cos_theta
/// has one value per entry): each (result member, response member) pair of
/// `vectors` holds d_i values per entry, of `matrices` d_i x d_i row-major.
template <typename Result, typename Response>
Result perEntryResult(
    const Response& r,
    std::initializer_list<std::pair<std::vector<Eigen::VectorXd> Result::*, std::vector<double> Response::*>> vectors,
    std::initializer_list<std::pair<std::vector<Eigen::MatrixXd> Result::*, std::vector<double> Response::*>> matrices)
{
  Result out;
  out.bodies = r.bodies;
  out.dofs = r.dofs;
  const std::size_t entries = r.cos_theta.size();
  out.configurations = out.bodies.empty() ? 0 : entries / out.bodies.size();
  for (const auto& [to, from] : vectors)
    out.*to = perEntryVectors(r.*from, r.dofs, entries);
  for (const auto& [to, from] : matrices)
    out.*to = perEntryMatrices(r.*from, r.dofs, entries);
  out.cos_theta = r.cos_theta;
  return out;
}

inline InverseDynamicsResult toInverseDynamics(const diff_rigid_body::InverseDynamics::Response& r)
{
  using Out = InverseDynamicsResult;
  using In = diff_rigid_body::InverseDynamics::Response;
  return perEntryResult<Out>(r,
                             { { &Out::tau, &In::tau },
                               { &Out::velocity_terms, &In::velocity_terms },
                               { &Out::gravity_terms, &In::gravity_terms } },
                             { { &Out::coriolis_matrices, &In::coriolis_matrices },
                               { &Out::dtau_dq, &In::dtau_dq },
                               { &Out::dtau_dqdot, &In::dtau_dqdot } });
}

inline ForwardDynamicsResult toForwardDynamics(const diff_rigid_body::ForwardDynamics::Response& r)
{
  using Out = ForwardDynamicsResult;
  using In = diff_rigid_body::ForwardDynamics::Response;
  return perEntryResult<Out>(r, { { &Out::qddot, &In::qddot } },
                             { { &Out::dqddot_dq, &In::dqddot_dq },
                               { &Out::dqddot_dqdot, &In::dqddot_dqdot },
                               { &Out::dqddot_dtau, &In::dqddot_dtau } });
}

/// get_vertex_jacobians of K configurations: one block of positions and J per configuration.
inline std::vector<VertexJacobians> toVertexJacobians(const diff_rigid_body::GetVertexJacobians::Response& r,
                                                      std::size_t K)
{
  const Eigen::Index n = detail::vertexCount(r.positions.size(), K);
  const Eigen::Index d = n ? static_cast<Eigen::Index>(r.jacobians.size() / (3 * n * K)) : 0;
  std::vector<VertexJacobians> out(K);
  for (std::size_t k = 0; k < K; ++k)
  {
    out[k].positions = Eigen::Map<const Eigen::Matrix3Xd>(r.positions.data() + 3 * n * k, 3, n);
    out[k].J = Eigen::Map<const StackedJacobians>(r.jacobians.data() + 3 * n * d * k, 3 * n, d);
  }
  return out;
}

/// get_vertex_jacobians_compact of K configurations in Scalar (double, or float for the float32
/// fields): one block of positions and Jr per configuration (Jr with 0 rows for `positions_only`).
template <typename Scalar>
std::vector<VertexRotationJacobians<Scalar>> toRotationJacobians(
    const diff_rigid_body::GetVertexJacobiansCompact::Response& r, std::size_t K, bool positions_only)
{
  const std::vector<Scalar>& positions = detail::compactField<Scalar>(r.positions, r.positions_f32);
  const std::vector<Scalar>& jacobians = detail::compactField<Scalar>(r.rotation_jacobians, r.rotation_jacobians_f32);
  const Eigen::Index n = detail::vertexCount(positions.size(), K);
  const Eigen::Index rows = positions_only ? 0 : 3 * n;
  const Eigen::Index columns = rows ? static_cast<Eigen::Index>(jacobians.size() / (rows * K)) : 0;
  std::vector<VertexRotationJacobians<Scalar>> out(K);
  for (std::size_t k = 0; k < K; ++k)
  {
    out[k].positions = Eigen::Map<const Eigen::Matrix<Scalar, 3, Eigen::Dynamic>>(positions.data() + 3 * n * k, 3, n);
    out[k].Jr = Eigen::Map<const typename VertexRotationJacobians<Scalar>::StackedRotationJacobians>(
        jacobians.data() + rows * columns * k, rows, columns);
  }
  return out;
}

/// backprop of K configurations: dL/dx (d values) per configuration.
inline std::vector<Eigen::VectorXd> toGradients(const diff_rigid_body::Backprop::Response& r, std::size_t K)
{
  const Eigen::Index d = K ? static_cast<Eigen::Index>(r.gradient.size() / K) : 0;
  std::vector<Eigen::VectorXd> out(K);
  for (std::size_t k = 0; k < K; ++k)
    out[k] = Eigen::Map<const Eigen::VectorXd>(r.gradient.data() + d * k, d);
  return out;
}

}  // namespace diff_rigid_body_ros
