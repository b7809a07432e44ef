// Mass properties of a link or a composite of links, and the rules that
// sort what a description gives into undefined (refused) and implausible
// (loaded with a warning); docs/interface.md, "Inertia from real URDFs".
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

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
/// into two kinds (docs/interface.md, "Inertia from real URDFs"):
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

}  // namespace diff_rigid_body
