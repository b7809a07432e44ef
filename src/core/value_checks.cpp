#include "value_checks.h"

#include <cmath>
#include <sstream>

#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace detail
{
std::string formatVector(const Eigen::Vector3d& v)
{
  std::ostringstream out;
  out.precision(17);
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

std::string formatMatrix(const Eigen::Matrix3d& m)
{
  std::ostringstream out;
  out.precision(17);
  out << "[[" << m(0, 0) << ", " << m(0, 1) << ", " << m(0, 2) << "], [" << m(1, 0) << ", " << m(1, 1) << ", "
      << m(1, 2) << "], [" << m(2, 0) << ", " << m(2, 1) << ", " << m(2, 2) << "]]";
  return out.str();
}

void checkPositiveFinite(const std::string& where, const char* name, double value, const char* unit)
{
  if (!std::isfinite(value) || !(value > 0.0))
  {
    std::ostringstream why;
    why.precision(17);
    why << where << ": " << name << " must be finite and > 0 " << unit << ", got " << value;
    throw InvalidArgumentError(why.str());
  }
}

Eigen::Matrix3d symmetrized(const Eigen::Matrix3d& m)
{
  return 0.5 * (m + m.transpose());
}

Eigen::Matrix3d inertiaFromSecondMoment(const Eigen::Matrix3d& C)
{
  return C.trace() * Eigen::Matrix3d::Identity() - C;
}
}  // namespace detail
}  // namespace diff_rigid_body
