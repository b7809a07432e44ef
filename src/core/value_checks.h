// Checks and formats shared by the core's files (not installed): the text of
// vectors and matrices in error messages, the "finite and > 0" rule, and the
// inertia identities used by every mass-property source.
#pragma once

#include <string>

#include <Eigen/Core>

namespace diff_rigid_body
{
namespace detail
{
/// "(x, y, z)" with 17 significant digits.
std::string formatVector(const Eigen::Vector3d& v);

/// "[[a, b, c], [d, e, f], [g, h, i]]" with 17 significant digits.
std::string formatMatrix(const Eigen::Matrix3d& m);

/// Throws InvalidArgumentError "<where>: <name> must be finite and > 0 <unit>, got <value>".
void checkPositiveFinite(const std::string& where, const char* name, double value, const char* unit);

/// (m + m^T) / 2.
Eigen::Matrix3d symmetrized(const Eigen::Matrix3d& m);

/// Inertia of a body with second moment C = integral rho x x^T dV about its
/// COM: I = tr(C) I3 - C.
Eigen::Matrix3d inertiaFromSecondMoment(const Eigen::Matrix3d& C);
}  // namespace detail
}  // namespace diff_rigid_body
