// The cos_theta of ~get_frame_jacobians (SceneQueries::frameJacobians): the
// cosine of each configuration's free-root pitch, taken from the sines and
// cosines forward kinematics computed (sinCos), against the 256-bit MPFR
// cosine of the same double theta: at gimbal lock (theta = +-pi/2 and
// +-pi/2 +- 10^-k), at large angles (past sinCos's fast range too) and at
// random. 1 for a fixed base.
#include <unsupported/Eigen/MPRealSupport>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "../support/oracles.h"
#include "../support/plumbing_scenes.h"

namespace drb = diff_rigid_body;
using namespace drb_test;
using mpfr::mpreal;

namespace
{
/// The pitches of the test: gimbal lock and near it, large angles, random.
std::vector<double> pitches()
{
  Random rng(2917);
  std::vector<double> thetas = gimbalLockThetas();
  for (const double a : largeAngles())
    thetas.push_back(a);
  thetas.push_back(2.5e6);  // past kSinCosFastLimit: std::cos
  for (int s = 0; s < 200; ++s)
    thetas.push_back(rng.uniform(-kPi, kPi));
  return thetas;
}
}  // namespace

TEST(FrameCosTheta, IsTheCosineOfEachConfigurationsPitch)
{
  // The free body cube, and the arm's floating root below which revolute
  // joints hold the first sine and cosine slots (one frame asked for: only
  // its path's joints are computed).
  const drb::SceneQueries queries(plumbing::scene());
  const std::vector<double> thetas = pitches();
  struct Case
  {
    const char* body;
    std::vector<std::string> frames;
    std::vector<double> joints;
  };
  for (const Case& c : { Case{ "cube", {}, {} }, Case{ "arm", { "fore" }, { 0.4, -0.5, 0.05 } } })
  {
    std::vector<double> q;
    for (const double theta : thetas)
    {
      q.insert(q.end(), { 0.3, theta, -1.1, 0.5, -0.2, 2.0 });
      q.insert(q.end(), c.joints.begin(), c.joints.end());
    }
    drb::FrameJacobianAnswer answer;
    queries.frameJacobians(queries.initialState(), c.body, c.frames, q, {}, 2, false, answer);
    ASSERT_EQ(answer.cos_theta.size(), thetas.size()) << c.body;
    double worst = 0.0, worst_relative = 0.0;
    for (std::size_t k = 0; k < thetas.size(); ++k)
    {
      const mpreal exact = mpfr::cos(mpreal(thetas[k], 256));
      // sinCos's bound (sin_cos.h): about 2 x 2^-53 absolute. Near the lock the
      // cosine is the reduced angle theta - pi/2 itself, relative to which the
      // error is that of pi/2 in three parts (about 2^-103): at the double
      // nearest pi/2, 6.1e-17, that is 6 ulp.
      const double error = mpfr::abs(mpreal(answer.cos_theta[k], 256) - exact).toDouble();
      const double relative = error / mpfr::abs(exact).toDouble();
      EXPECT_LE(error, 2.5 * kEps / 2) << c.body << ", theta = " << thetas[k];
      EXPECT_LE(relative, 16 * kEps) << c.body << ", theta = " << thetas[k];
      worst = std::max(worst, error / (kEps / 2));
      worst_relative = std::max(worst_relative, relative / kEps);
    }
    std::printf("[measured] %s: frame cos_theta vs MPFR cos: %.3g x 2^-53 absolute, %.3g ulp relative\n", c.body,
                worst, worst_relative);
  }
}

TEST(FrameCosTheta, IsOneForAFixedBase)
{
  const drb::SceneQueries queries(plumbing::scene());
  drb::FrameJacobianAnswer answer;
  queries.frameJacobians(queries.initialState(), "crane", {}, { 0.7, 0.25, -0.3, 1.5 }, {}, 0, true, answer);
  ASSERT_EQ(answer.cos_theta.size(), 2u);
  EXPECT_EQ(answer.cos_theta[0], 1.0);
  EXPECT_EQ(answer.cos_theta[1], 1.0);
}
