// Each inertia validity rule gives its own clear error naming the link and the rule.
#include <cfloat>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/rigid_body.h"

using diff_rigid_body::InvalidInertiaError;
using diff_rigid_body::validateMassProperties;

namespace
{
// Expects validateMassProperties to throw, with both `link` and `rule` in the message.
void expectRejected(double mass, const Eigen::Matrix3d& inertia, const std::string& rule)
{
  try
  {
    validateMassProperties("link 'probe'", mass, inertia);
    FAIL() << "accepted, expected a '" << rule << "' error";
  }
  catch (const InvalidInertiaError& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("link 'probe'"), std::string::npos) << message;
    EXPECT_NE(message.find(rule), std::string::npos) << message;
  }
}
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
  expectRejected(std::numeric_limits<double>::quiet_NaN(), Eigen::Matrix3d::Identity(), "mass must be finite");
  expectRejected(std::numeric_limits<double>::infinity(), Eigen::Matrix3d::Identity(), "mass must be finite");
}

TEST(Validation, MassMustBePositive)
{
  expectRejected(0.0, Eigen::Matrix3d::Identity(), "mass must be > 0");
  expectRejected(-1.0, Eigen::Matrix3d::Identity(), "mass must be > 0");
  expectRejected(-std::numeric_limits<double>::denorm_min(), Eigen::Matrix3d::Identity(), "mass must be > 0");
}

TEST(Validation, InertiaMustBeFinite)
{
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  inertia(1, 2) = std::numeric_limits<double>::quiet_NaN();
  expectRejected(1.0, inertia, "inertia must be finite");
  inertia(1, 2) = std::numeric_limits<double>::infinity();
  expectRejected(1.0, inertia, "inertia must be finite");
}

TEST(Validation, InertiaMustBeSymmetric)
{
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  inertia(0, 1) = 0.1;
  expectRejected(1.0, inertia, "inertia must be symmetric");
}

TEST(Validation, InertiaMustBePositiveDefinite)
{
  expectRejected(1.0, Eigen::Vector3d(1, 1, 0).asDiagonal(), "positive-definite");
  expectRejected(1.0, Eigen::Vector3d(1, -1, 1).asDiagonal(), "positive-definite");
  // Positive diagonal but indefinite through its products of inertia.
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  inertia(0, 1) = inertia(1, 0) = 2.0;
  expectRejected(1.0, inertia, "positive-definite");
}

TEST(Validation, PrincipalMomentsObeyTriangleInequality)
{
  expectRejected(1.0, Eigen::Vector3d(1, 1, 2.5).asDiagonal(), "triangle inequality");
  // Rotated out of its principal axes, the same tensor is still caught.
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  expectRejected(1.0, Q * Eigen::Vector3d(1, 1, 2.5).asDiagonal() * Q.transpose(), "triangle inequality");
  // Just inside Drake's tolerance eps = 16 DBL_EPSILON max(1, trace/2) is accepted.
  EXPECT_NO_THROW(validateMassProperties("edge", 1.0, Eigen::Vector3d(1, 1, 2 + 8 * DBL_EPSILON).asDiagonal()));
}
