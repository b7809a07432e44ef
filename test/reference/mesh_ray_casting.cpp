#include "mesh_ray_casting.h"

#include <algorithm>

#include "diff_rigid_body/exceptions.h"
#include "value_checks.h"

namespace diff_rigid_body
{
namespace
{
/// Edge function of the directed edge a -> b at the ray (y, z), with the
/// sign the perturbed ray would give (see crossTriangle).
struct EdgeSide
{
  double value;  ///< E [m^2]
  int sign;      ///< sign of the perturbed E; 0 only for an edge parallel to x
};

EdgeSide edgeSide(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double y, double z)
{
  const bool reversed = (b.y() < a.y()) || (b.y() == a.y() && b.z() < a.z());
  const Eigen::Vector3d& p = reversed ? b : a;
  const Eigen::Vector3d& q = reversed ? a : b;
  const double dy = q.y() - p.y();
  const double dz = q.z() - p.z();
  const double value = dy * (z - p.z()) - dz * (y - p.y());
  int sign;
  if (value != 0.0)
    sign = value > 0.0 ? 1 : -1;
  else if (dz != 0.0)  // dE/dy = -dz
    sign = dz < 0.0 ? 1 : -1;
  else  // dE/dz = dy
    sign = dy > 0.0 ? 1 : (dy < 0.0 ? -1 : 0);
  return reversed ? EdgeSide{ -value, -sign } : EdgeSide{ value, sign };
}
}  // namespace

bool crossTriangle(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1, const Eigen::Vector3d& v2, double y,
                   double z, RayCrossing* crossing)
{
  const EdgeSide e0 = edgeSide(v1, v2, y, z);
  if (e0.sign == 0)
    return false;
  const EdgeSide e1 = edgeSide(v2, v0, y, z);
  if (e1.sign != e0.sign)
    return false;
  const EdgeSide e2 = edgeSide(v0, v1, y, z);
  if (e2.sign != e0.sign)
    return false;
  const double sum = e0.value + e1.value + e2.value;
  const double x_min = std::min({ v0.x(), v1.x(), v2.x() });
  const double x_max = std::max({ v0.x(), v1.x(), v2.x() });
  double x = (sum != 0.0) ? (e0.value * v0.x() + e1.value * v1.x() + e2.value * v2.x()) / sum :
                            (v0.x() + v1.x() + v2.x()) / 3.0;
  crossing->x = std::min(std::max(x, x_min), x_max);
  crossing->direction = e0.sign;
  return true;
}

int meshWindingNumber(const TriangleMesh& mesh, const Eigen::Vector3d& point)
{
  if (!point.allFinite())
    throw InvalidArgumentError("meshWindingNumber: point must be finite, got " + detail::formatVector(point));
  int winding = 0;
  for (const auto& triangle : mesh.triangles)
  {
    RayCrossing crossing;
    if (crossTriangle(mesh.vertices.col(triangle[0]), mesh.vertices.col(triangle[1]), mesh.vertices.col(triangle[2]),
                      point.y(), point.z(), &crossing) &&
        crossing.x > point.x())
      winding += crossing.direction;
  }
  return winding;
}

}  // namespace diff_rigid_body
