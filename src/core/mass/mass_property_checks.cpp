#include "diff_rigid_body/mass/mass_property_checks.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "diff_rigid_body/exceptions.h"
#include "value_checks.h"

namespace diff_rigid_body
{
using detail::formatMatrix;

namespace
{
/// The principal-moment part of checkMassProperties, for a finite tensor
/// that is symmetric to kInertiaSymmetryTolerance.
std::vector<std::string> checkPrincipalMoments(const std::string& where, const Eigen::Matrix3d& inertia)
{
  std::ostringstream why;
  why.precision(17);
  const Eigen::Matrix3d symmetric = 0.5 * (inertia + inertia.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(symmetric, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d moments = solver.eigenvalues();  // ascending
  const double eps = 16.0 * DBL_EPSILON * std::max(1.0, moments.cwiseAbs().sum() / 2.0);
  if (!(moments[0] > 0.0))
  {
    why << where << ": inertia must be positive-definite, but its smallest principal moment is " << moments[0]
        << " kg m^2 in " << formatMatrix(inertia);
    if (moments[0] < -eps)  // a negative moment: no mass distribution has it
      throw InvalidInertiaError(why.str());
    return { why.str() };  // a zero moment: a point mass or a thin rod, M singular in rotation
  }
  if (moments[0] < DBL_MIN)
  {
    why << where << ": principal moments must be normal numbers (>= " << DBL_MIN
        << " kg m^2), but the smallest is " << moments[0] << " kg m^2 in " << formatMatrix(inertia);
    throw InvalidInertiaError(why.str());
  }
  if (moments[0] + moments[1] < moments[2] - eps)
  {
    why << where << ": principal moments break the triangle inequality I1 + I2 >= I3: " << moments[0] << " + "
        << moments[1] << " < " << moments[2] << " kg m^2";
    return { why.str() };
  }
  return {};
}
}  // namespace

std::vector<std::string> checkMassProperties(const std::string& where, double mass, const Eigen::Matrix3d& inertia)
{
  std::ostringstream why;
  why.precision(17);
  if (!std::isfinite(mass))
  {
    why << where << ": mass must be finite, got " << mass;
    throw InvalidInertiaError(why.str());
  }
  if (mass < 0.0)
  {
    why << where << ": mass must be > 0 kg, got " << mass;
    throw InvalidInertiaError(why.str());
  }
  if (mass == 0.0)  // +0 or -0: a massless frame (tool frames, flanges)
  {
    why << where << ": mass must be > 0 kg, got " << mass;
    return { why.str() };
  }
  if (mass < DBL_MIN)  // subnormal: m x rounds away, so the COM and inertia would be silently wrong
  {
    why << where << ": mass must be a normal number (>= " << DBL_MIN << " kg), got " << mass;
    throw InvalidInertiaError(why.str());
  }
  if (!inertia.allFinite())
  {
    why << where << ": inertia must be finite, got " << formatMatrix(inertia);
    throw InvalidInertiaError(why.str());
  }
  const double scale = std::max(1.0, inertia.cwiseAbs().maxCoeff());
  const double asymmetry = (inertia - inertia.transpose()).cwiseAbs().maxCoeff();
  if (asymmetry > kInertiaSymmetryTolerance * scale)
  {
    why << where << ": inertia must be symmetric, but |I - I^T| = " << asymmetry << " in " << formatMatrix(inertia);
    throw InvalidInertiaError(why.str());
  }
  return checkPrincipalMoments(where, inertia);
}

void validateMassProperties(const std::string& where, double mass, const Eigen::Matrix3d& inertia)
{
  const std::vector<std::string> implausible = checkMassProperties(where, mass, inertia);
  if (!implausible.empty())
    throw InvalidInertiaError(implausible.front());
}

}  // namespace diff_rigid_body
