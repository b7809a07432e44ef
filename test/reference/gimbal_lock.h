// The gimbal-lock diagnostic, as a function of its own (the node reports
// cos(theta) from the RpyTrig of the mass matrix). Reference for tests.
#pragma once

#include <cmath>

namespace diff_rigid_body
{
/// cos(theta): the gimbal-lock diagnostic. 1 far from the singularity, 0 at
/// theta = +-pi/2, where the angular block of M loses rank.
template <typename Scalar>
Scalar gimbalLockCosine(const Scalar& theta)
{
  using std::cos;
  return cos(theta);
}

}  // namespace diff_rigid_body
