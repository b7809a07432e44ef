// Closed-form mass properties of the URDF primitives (mass_properties.h).
#include "diff_rigid_body/mass/mass_properties.h"
#include "value_checks.h"

namespace diff_rigid_body
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
}  // namespace

using detail::checkPositiveFinite;

MassProperties boxMassProperties(double density, const Eigen::Vector3d& size)
{
  checkPositiveFinite("box", "density", density, "kg/m^3");
  checkPositiveFinite("box", "size x", size.x(), "m");
  checkPositiveFinite("box", "size y", size.y(), "m");
  checkPositiveFinite("box", "size z", size.z(), "m");
  MassProperties result;
  result.mass = density * size.prod();
  const Eigen::Vector3d sq = size.cwiseAbs2();
  result.inertia.diagonal() << sq.y() + sq.z(), sq.x() + sq.z(), sq.x() + sq.y();
  result.inertia *= result.mass / 12.0;
  return result;
}

MassProperties sphereMassProperties(double density, double radius)
{
  checkPositiveFinite("sphere", "density", density, "kg/m^3");
  checkPositiveFinite("sphere", "radius", radius, "m");
  MassProperties result;
  result.mass = density * (4.0 / 3.0) * kPi * radius * radius * radius;
  result.inertia.diagonal().setConstant(0.4 * result.mass * radius * radius);
  return result;
}

MassProperties cylinderMassProperties(double density, double radius, double length)
{
  checkPositiveFinite("cylinder", "density", density, "kg/m^3");
  checkPositiveFinite("cylinder", "radius", radius, "m");
  checkPositiveFinite("cylinder", "length", length, "m");
  MassProperties result;
  result.mass = density * kPi * radius * radius * length;
  const double transverse = result.mass * (3.0 * radius * radius + length * length) / 12.0;
  result.inertia.diagonal() << transverse, transverse, 0.5 * result.mass * radius * radius;
  return result;
}

}  // namespace diff_rigid_body
