// Composites of rigidly joined parts: the parallel-axis theorem and the
// change of frame of mass properties (mass_properties.h).
#include <cmath>
#include <sstream>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mass_properties.h"
#include "value_checks.h"

namespace diff_rigid_body
{
namespace
{
/// Deviation from orthonormality accepted in a pose's rotation, |R^T R - I|_max.
constexpr double kRotationOrthonormalityTolerance = 1e-9;

/// Throws InvalidInertiaError "<where>: part <k>: ..." unless the pose is
/// finite and orthonormal, the mass finite and >= 0, the COM and inertia finite.
void checkPart(const std::string& where, std::size_t k, const Eigen::Isometry3d& pose, const MassProperties& part)
{
  std::ostringstream why;
  why.precision(17);
  why << where << ": part " << k << ": ";
  if (!pose.matrix().allFinite())
  {
    why << "pose must be finite";
    throw InvalidInertiaError(why.str());
  }
  const double non_orthonormality =
      (pose.linear().transpose() * pose.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (non_orthonormality > kRotationOrthonormalityTolerance)
  {
    why << "pose rotation is not orthonormal (|R^T R - I| = " << non_orthonormality << ")";
    throw InvalidInertiaError(why.str());
  }
  if (!std::isfinite(part.mass) || part.mass < 0.0)
  {
    why << "mass must be finite and >= 0 kg, got " << part.mass;
    throw InvalidInertiaError(why.str());
  }
  if (!part.com.allFinite())
  {
    why << "COM must be finite, got " << detail::formatVector(part.com);
    throw InvalidInertiaError(why.str());
  }
  if (!part.inertia.allFinite())
  {
    why << "inertia must be finite";
    throw InvalidInertiaError(why.str());
  }
}
}  // namespace

Eigen::Matrix3d pointMassInertia(double mass, const Eigen::Vector3d& offset)
{
  return mass * (offset.squaredNorm() * Eigen::Matrix3d::Identity() - offset * offset.transpose());
}

MassProperties transformMassProperties(const Eigen::Isometry3d& X_BA, const MassProperties& in_A)
{
  MassProperties in_B;
  in_B.mass = in_A.mass;
  in_B.com = X_BA * in_A.com;
  in_B.inertia = detail::symmetrized(X_BA.linear() * in_A.inertia * X_BA.linear().transpose());
  return in_B;
}

MassProperties combineMassProperties(const std::vector<std::pair<Eigen::Isometry3d, MassProperties>>& parts,
                                     const std::string& where)
{
  if (parts.empty())
    throw InvalidInertiaError(where + ": no parts to combine");
  std::vector<MassProperties> in_target;
  in_target.reserve(parts.size());
  double mass = 0.0;
  Eigen::Vector3d weighted_com = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < parts.size(); ++k)
  {
    checkPart(where, k, parts[k].first, parts[k].second);
    in_target.push_back(transformMassProperties(parts[k].first, parts[k].second));
    mass += parts[k].second.mass;
    weighted_com += parts[k].second.mass * in_target.back().com;
  }
  if (!(mass > 0.0) || !std::isfinite(mass))
  {
    std::ostringstream why;
    why.precision(17);
    why << where << ": total mass must be finite and > 0 kg, got " << mass;
    throw InvalidInertiaError(why.str());
  }
  MassProperties result;
  result.mass = mass;
  result.com = weighted_com / mass;
  for (const MassProperties& part : in_target)
    result.inertia += part.inertia + pointMassInertia(part.mass, part.com - result.com);
  result.inertia = detail::symmetrized(result.inertia);
  return result;
}

}  // namespace diff_rigid_body
