// Frame and centre-of-mass Jacobians for RigidBodyClient (rigid_body_client.h) and RigidBodyPool
// (rigid_body_pool.h): the result types and the responses' split per frame or body (requests:
// detail::requestOf, client_requests.h).
//
// Columns are d/dx' of the body's coordinates x (for a floating root: the Euler-angle rates). A
// frame's six rows are linear [m/s] then angular [rad/s] per unit rate, in the reference asked for,
// with Pinocchio's meanings: WORLD (fixed_frame axes, the velocity of the link's point at
// fixed_frame's origin), LOCAL (the link's axes, its origin's velocity), LOCAL_WORLD_ALIGNED
// (fixed_frame axes, the link origin's velocity: the usual end-effector Jacobian).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <diff_rigid_body/GetCenterOfMass.h>
#include <diff_rigid_body/GetFrameJacobians.h>

#include "diff_rigid_body_ros/client_requests.h"
#include "diff_rigid_body_ros/client_types.h"

namespace diff_rigid_body_ros
{
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// GetFrameJacobians' `reference`.
enum class FrameReference : std::uint8_t
{
  World = diff_rigid_body::GetFrameJacobians::Request::WORLD,
  Local = diff_rigid_body::GetFrameJacobians::Request::LOCAL,
  LocalWorldAligned = diff_rigid_body::GetFrameJacobians::Request::LOCAL_WORLD_ALIGNED,
};

/// get_frame_jacobians of K configurations and F frames; entry index(k, f) = k F + f.
struct FrameJacobians
{
  std::vector<std::string> frames;
  std::uint32_t dofs = 0;
  std::size_t configurations = 0;
  std::vector<Eigen::Isometry3d> poses;  ///< the frame in fixed_frame [m]
  std::vector<Matrix6Xd> J;              ///< 6 x d: rows linear then angular, per unit x'
  std::vector<Vector6d> bias;            ///< J'x' at x'' = 0, when asked (else empty)
  std::vector<double> cos_theta;         ///< per configuration (1 for a fixed base)

  std::size_t index(std::size_t k, std::size_t f) const { return k * frames.size() + f; }
};

/// get_center_of_mass of K configurations and n bodies; entry index(k, i) = k n + i.
struct CenterOfMassResult
{
  std::vector<std::string> bodies;
  std::vector<std::uint32_t> dofs;
  std::size_t configurations = 0;
  std::vector<double> masses;           ///< per body [kg]
  std::vector<Eigen::Vector3d> com;     ///< fixed_frame [m]
  std::vector<Eigen::Matrix3Xd> J;      ///< 3 x d_i = dc/dx, when asked (else empty)
  std::vector<Eigen::Vector3d> bias;    ///< c'' at x'' = 0 [m/s^2], when asked (else empty)
  std::vector<double> cos_theta;

  std::size_t index(std::size_t k, std::size_t i) const { return k * bodies.size() + i; }
};

inline FrameJacobians toFrameJacobians(const diff_rigid_body::GetFrameJacobians::Response& r)
{
  using RowMajor = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>;
  FrameJacobians out;
  out.frames = r.frames;
  out.dofs = r.dofs;
  out.configurations = r.cos_theta.size();
  const std::size_t entries = r.poses.size() / 12;
  const Eigen::Index d = r.dofs;
  for (std::size_t n = 0; n < entries; ++n)
  {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Map<const Eigen::Vector3d>(r.poses.data() + 12 * n);
    pose.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.poses.data() + 12 * n + 3);
    out.poses.push_back(pose);
    out.J.emplace_back(Eigen::Map<const RowMajor>(r.jacobians.data() + 6 * d * n, 6, d));
    if (!r.acceleration_bias.empty())
      out.bias.emplace_back(Eigen::Map<const Vector6d>(r.acceleration_bias.data() + 6 * n));
  }
  out.cos_theta = r.cos_theta;
  return out;
}

inline CenterOfMassResult toCenterOfMass(const diff_rigid_body::GetCenterOfMass::Response& r)
{
  using RowMajor = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>;
  CenterOfMassResult out;
  out.bodies = r.bodies;
  out.dofs = r.dofs;
  out.masses = r.masses;
  const std::size_t n = r.bodies.size(), entries = r.cos_theta.size();
  out.configurations = n ? entries / n : 0;
  std::size_t column = 0;  // 3 d_i values per entry, in entry order
  for (std::size_t e = 0; e < entries; ++e)
  {
    out.com.emplace_back(Eigen::Map<const Eigen::Vector3d>(r.com.data() + 3 * e));
    if (r.jacobians.empty())
      continue;
    const Eigen::Index d = r.dofs[e % n];
    out.J.emplace_back(Eigen::Map<const RowMajor>(r.jacobians.data() + column, 3, d));
    out.bias.emplace_back(Eigen::Map<const Eigen::Vector3d>(r.acceleration_bias.data() + 3 * e));
    column += 3 * static_cast<std::size_t>(d);
  }
  out.cos_theta = r.cos_theta;
  return out;
}

}  // namespace diff_rigid_body_ros
