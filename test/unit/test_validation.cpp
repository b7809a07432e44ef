// Each inertia validity rule gives its own clear error naming the link and the rule.
#include <cfloat>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/mass/mass_property_checks.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "../support/expect_throws.h"

using diff_rigid_body::InvalidInertiaError;
using diff_rigid_body::validateMassProperties;

namespace
{
constexpr const char* kProbe = "link 'probe'";
}  // namespace

TEST(Validation, AcceptsPhysicalInertia)
{
  EXPECT_NO_THROW(validateMassProperties("l", 2.0, Eigen::Vector3d(1, 2, 2.5).asDiagonal()));
  // A thin rod sits on the edge of the triangle inequality: I = diag(eps, I, I).
  EXPECT_NO_THROW(validateMassProperties("rod", 1.0, Eigen::Vector3d(1e-12, 1, 1).asDiagonal()));
  // Masses across the documented range.
  EXPECT_NO_THROW(validateMassProperties("tiny", 1e-9, Eigen::Matrix3d::Identity() * 1e-15));
  EXPECT_NO_THROW(validateMassProperties("huge", 1e9, Eigen::Matrix3d::Identity() * 1e9));
}

TEST(Validation, MassMustBeFinite)
{
  DRB_EXPECT_THROWS_MESSAGE(
      validateMassProperties(kProbe, std::numeric_limits<double>::quiet_NaN(), Eigen::Matrix3d::Identity()),
      InvalidInertiaError, kProbe, "mass must be finite");
  DRB_EXPECT_THROWS_MESSAGE(
      validateMassProperties(kProbe, std::numeric_limits<double>::infinity(), Eigen::Matrix3d::Identity()),
      InvalidInertiaError, kProbe, "mass must be finite");
}

TEST(Validation, MassMustBePositive)
{
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 0.0, Eigen::Matrix3d::Identity()), InvalidInertiaError,
                            kProbe, "mass must be > 0");
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, -1.0, Eigen::Matrix3d::Identity()), InvalidInertiaError,
                            kProbe, "mass must be > 0");
  DRB_EXPECT_THROWS_MESSAGE(
      validateMassProperties(kProbe, -std::numeric_limits<double>::denorm_min(), Eigen::Matrix3d::Identity()),
      InvalidInertiaError, kProbe, "mass must be > 0");
}

TEST(Validation, InertiaMustBeFinite)
{
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  inertia(1, 2) = std::numeric_limits<double>::quiet_NaN();
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 1.0, inertia), InvalidInertiaError, kProbe,
                            "inertia must be finite");
  inertia(1, 2) = std::numeric_limits<double>::infinity();
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 1.0, inertia), InvalidInertiaError, kProbe,
                            "inertia must be finite");
}

TEST(Validation, InertiaMustBeSymmetric)
{
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  inertia(0, 1) = 0.1;
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 1.0, inertia), InvalidInertiaError, kProbe,
                            "inertia must be symmetric");
}

TEST(Validation, InertiaMustBePositiveDefinite)
{
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 1.0, Eigen::Vector3d(1, 1, 0).asDiagonal()),
                            InvalidInertiaError, kProbe, "positive-definite");
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 1.0, Eigen::Vector3d(1, -1, 1).asDiagonal()),
                            InvalidInertiaError, kProbe, "positive-definite");
  // Positive diagonal but indefinite through its products of inertia.
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  inertia(0, 1) = inertia(1, 0) = 2.0;
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 1.0, inertia), InvalidInertiaError, kProbe,
                            "positive-definite");
}

TEST(Validation, PrincipalMomentsObeyTriangleInequality)
{
  DRB_EXPECT_THROWS_MESSAGE(validateMassProperties(kProbe, 1.0, Eigen::Vector3d(1, 1, 2.5).asDiagonal()),
                            InvalidInertiaError, kProbe, "triangle inequality");
  // Rotated out of its principal axes, the same tensor is still caught.
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  DRB_EXPECT_THROWS_MESSAGE(
      validateMassProperties(kProbe, 1.0, Q * Eigen::Vector3d(1, 1, 2.5).asDiagonal() * Q.transpose()),
      InvalidInertiaError, kProbe, "triangle inequality");
  // Just inside Drake's tolerance eps = 16 DBL_EPSILON max(1, trace/2) is accepted.
  EXPECT_NO_THROW(validateMassProperties("edge", 1.0, Eigen::Vector3d(1, 1, 2 + 8 * DBL_EPSILON).asDiagonal()));
}

// requireFinite (every request array and every answer): each non-finite value, at every
// position of arrays of odd and even length, is refused by its index; the extreme finite values
// pass. Oracle: std::isfinite, value by value.
TEST(Validation, RequireFiniteRefusesEachNonFiniteValueByIndex)
{
  const double finite[] = { 0.0, -0.0, DBL_MAX, -DBL_MAX, DBL_MIN, std::numeric_limits<double>::denorm_min(), 1.5 };
  const double bad[] = { std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                         std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::signaling_NaN() };
  for (std::size_t count = 0; count <= 9; ++count)
  {
    std::vector<double> values(count);
    for (std::size_t i = 0; i < count; ++i)
      values[i] = finite[i % (sizeof finite / sizeof finite[0])];
    EXPECT_NO_THROW(diff_rigid_body::requireFinite(values.data(), count, "q")) << count;
    for (std::size_t at = 0; at < count; ++at)
      for (double value : bad)
      {
        std::vector<double> with_bad = values;
        with_bad[at] = value;
        ASSERT_FALSE(std::isfinite(with_bad[at]));
        try
        {
          diff_rigid_body::requireFinite(with_bad.data(), count, "q");
          ADD_FAILURE() << "accepted " << value << " at " << at << " of " << count;
        }
        catch (const diff_rigid_body::InvalidArgumentError& error)
        {
          EXPECT_NE(std::string(error.what()).find("q[" + std::to_string(at) + "]: not finite"), std::string::npos)
              << error.what();
        }
      }
  }
}
