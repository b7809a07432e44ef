// Responses of rigid_body_server's services as the client types of
// client_types.h (used by rigid_body_client.h).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include <diff_rigid_body/GetBodies.h>
#include <diff_rigid_body/GetMassMatrix.h>

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

}  // namespace diff_rigid_body_ros
