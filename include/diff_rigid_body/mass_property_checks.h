// The rigid-body model: mass, inertia, COM offset and body-frame vertices.
//
// Frames:
//   link frame  the URDF link frame of the body.
//   body frame  origin at the COM, axes of the link frame. A link-frame point
//               x maps to x - com_offset in the body frame.
// The state q = (phi, theta, psi, tx, ty, tz) gives the RPY angles of the
// link (= body) axes and the COM position t in the fixed frame, so the link
// origin sits at t - R com_offset.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "diff_rigid_body/types.h"

namespace diff_rigid_body
{
/// Mass properties of one link or composite, in a given frame.
struct MassProperties
{
  double mass = 0.0;                                    ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();        ///< COM in the frame [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();    ///< about the COM, frame axes [kg m^2]
};

/// Relative tolerance for the symmetry check of an inertia tensor:
/// |I - I^T| <= kInertiaSymmetryTolerance * max(1, max|I_ij|).
constexpr double kInertiaSymmetryTolerance = 1e-9;

/// Checks mass properties read from a description and sorts what is wrong
/// into two kinds (interface.md, "Inertia from real URDFs"):
///   - undefined, thrown as InvalidInertiaError: a non-finite or negative mass,
///     a subnormal mass (m x would round away), a non-finite or asymmetric
///     tensor, a negative or subnormal principal moment;
///   - implausible, returned (one message each, naming `where`): mass 0 (a
///     massless frame; its tensor is then not examined), a zero principal
///     moment (|I_min| <= eps), principal moments that break the triangle
///     inequality I1 + I2 >= I3 - eps.
/// eps = 16 DBL_EPSILON max(1, trace/2) (Drake's tolerance).
std::vector<std::string> checkMassProperties(const std::string& where, double mass, const Eigen::Matrix3d& inertia);

/// Strict form of checkMassProperties: also throws InvalidInertiaError for
/// the first implausible finding. Accepts only mass > 0 with a finite,
/// symmetric, positive-definite tensor that satisfies the triangle inequality.
void validateMassProperties(const std::string& where, double mass, const Eigen::Matrix3d& inertia);

/// One free rigid body of the scene.
struct RigidBody
{
  std::string name;                                          ///< body link name
  double mass = 0.0;                                         ///< [kg]
  Eigen::Matrix3d inertia_body = Eigen::Matrix3d::Identity();  ///< about the COM, body axes [kg m^2]
  Eigen::Vector3d com_offset = Eigen::Vector3d::Zero();      ///< COM in the link frame [m]
  Matrix3X<double> vertices;                                 ///< body frame, one per column [m]
};

}  // namespace diff_rigid_body
