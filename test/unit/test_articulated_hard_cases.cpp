// Articulated bodies (docs/interface.md, "Version 2") in the hard cases:
//   - 256-bit MPFR: crba<mpfr::mpreal> at the same x is the
//     reference for the double M: the floating tree at pitch pi/2 and
//     pi/2 +- 1e-k (k = 3, 6, 9), every fixture with its joints at their
//     limits, stretched straight and at random, and the zero-mass frames
//     (Panda's panda_link8 and panda_hand_tcp, UR5's ee_link, tool0 and
//     base, the simple pendulum's link3; the tree's massless wrist segment);
//   - the home poses (UR5 all zero, the Panda's SRDF "default"): M is
//     positive definite;
//   - a scene of free objects loads in model mode exactly as in free mode
//     (free objects, the same bits).
// The double error is measured in ulps of max|M| (ulp = spacing of doubles
// at max|M|).
#include <unsupported/Eigen/MPRealSupport>

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "diff_rigid_body/algorithm/free_body/mass_matrix.h"
#include "../support/articulated_fixtures.h"
#include "../support/body_models.h"

namespace drb = diff_rigid_body;
using namespace drb_test;
using namespace drb_test::articulated;
using mpfr::mpreal;
using drb_test::core_body::massMatrixAt;
namespace ub = drb_test::urdf;  // URDF text builders (urdf:: is urdfdom)

namespace
{
// M (double) vs M (256 bits) at the same x, in ulps of max|M|. An entry sums
// over the segments below both joints products of rounded twists (cross
// products of rotated axes, depth up to 9 for the Panda) and composite
// inertias about the reference point; each term is O(max|M|) for these
// bodies (reach ~1 m, no cancelling masses), so the error is a few ulps times
// the depth. Measured: 4.1 ulp (Panda), 2.2 ulp (floating tree at pitch
// pi/2 +- 1e-k). 16 ulps.
constexpr double kMpfrUlps = 16;
// dM/dx (forward-mode AD) vs the complex step: a few eps.
constexpr double kComplexStepTol = 8 * kEps;

using MatrixMp = Eigen::Matrix<mpreal, Eigen::Dynamic, Eigen::Dynamic>;
using VectorMp = Eigen::Matrix<mpreal, Eigen::Dynamic, 1>;

const LoadedBody& loaded(const std::string& name)
{
  for (const LoadedBody& b : loadedBodies())
    if (b.name == name)
      return b;
  throw std::runtime_error("no fixture " + name);
}

/// |M_double - M_256| / ulp(max|M_256|), the difference taken in 256 bits.
double mpfrUlps(const drb::BodyModel& body, const Eigen::VectorXd& x)
{
  const Eigen::MatrixXd M = massMatrixAt(body, x.data());
  const VectorMp x_mp = x.cast<mpreal>();
  const MatrixMp M_mp = massMatrixAt(body, x_mp.data());
  const mpreal err = (M.cast<mpreal>() - M_mp).cwiseAbs().maxCoeff();
  const double scale = M_mp.cwiseAbs().maxCoeff().toDouble();
  return err.toDouble() / ulp(scale);
}

/// Pitch values at and around gimbal lock: +-pi/2 and +-pi/2 +- 1e-k, k = 3, 6, 9.
std::vector<double> nearLockPitches()
{
  std::vector<double> pitches;
  for (const double base : { kHalfPi, -kHalfPi })
  {
    pitches.push_back(base);
    for (const int k : { 3, 6, 9 })
      for (const double sign : { 1.0, -1.0 })
        pitches.push_back(base + sign * std::pow(10.0, -k));
  }
  return pitches;
}
}  // namespace

TEST(ArticulatedHardCases, FloatingTreeNearGimbalLockMatchesMpfr256)
{
  mpreal::set_default_prec(256);
  Random rng(1211);
  const LoadedBody& b = loaded("floating_tree");
  MaxTracker ulps, derivative;
  for (const double pitch : nearLockPitches())
    for (const auto& [label, x0] : configurations(b.model, rng, 4))
    {
      Eigen::VectorXd x = x0;
      x[1] = pitch;
      const Eigen::MatrixXd M = massMatrixAt(b.body(), x.data());
      ASSERT_TRUE(M.allFinite()) << label << ", pitch " << pitch;
      const double e = mpfrUlps(b.body(), x);
      ulps.update(e);
      ASSERT_LE(e, kMpfrUlps) << label << ", pitch pi/2 offset " << pitch - kHalfPi << ", x = " << row(x);
      // dM/dx of the root angles against the complex step, relative to max(max|dM|, max|M|).
      const std::vector<Eigen::MatrixXd> dM = drb_test::core_body::massMatrixDerivativesAt(b.body(), x.data());
      double scale = maxAbs(M);
      for (const auto& d : dM)
        scale = std::max(scale, maxAbs(d));
      for (Eigen::Index j = 0; j < 3; ++j)
      {
        Eigen::VectorXcd xc = x.cast<Complex>();
        xc[j] += Complex(0.0, kComplexStepH);
        const Eigen::MatrixXd dM_cs = massMatrixAt(b.body(), xc.data()).imag() / kComplexStepH;
        const double e_d = maxAbs(dM[j] - dM_cs) / scale;
        derivative.update(e_d);
        ASSERT_LE(e_d, kComplexStepTol) << label << ", pitch " << pitch << ", d/dx_" << j;
      }
    }
  std::printf("[measured] floating tree near gimbal lock: M vs 256-bit MPFR %.3g ulp of max|M|; "
              "dM/d(angles) vs complex step %.3g eps\n",
              ulps.value, derivative.value / kEps);
}

TEST(ArticulatedHardCases, FixturesAtLimitsStretchedAndRandomMatchMpfr256)
{
  mpreal::set_default_prec(256);
  Random rng(1212);
  for (const LoadedBody& b : loadedBodies())
  {
    MaxTracker ulps;
    for (const auto& [label, x] : configurations(b.model, rng, 20))
    {
      const double e = mpfrUlps(b.body(), x);
      ulps.update(e);
      ASSERT_LE(e, kMpfrUlps) << b.name << ", " << label << ", x = " << row(x);
    }
    std::printf("[measured] %s: M vs 256-bit MPFR %.3g ulp of max|M|\n", b.name.c_str(), ulps.value);
  }
}

TEST(ArticulatedHardCases, ZeroMassFramesAddNoMassAndKeepTheirVertices)
{
  // The zero-mass frames are merged into their segments: each fixture's
  // segments are exactly its moving links, and the frames move with them.
  struct Expected
  {
    const char* fixture;
    std::vector<std::string> segment_links;
  };
  const std::vector<Expected> expected = {
    { "ur5", { "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link" } },
    { "double_pendulum_simple", { "link1", "link2" } },
    { "panda",
      { "panda_link1", "panda_link2", "panda_link3", "panda_link4", "panda_link5", "panda_link6", "panda_link7",
        "panda_leftfinger", "panda_rightfinger" } },
    { "floating_tree", { "torso", "left_thigh", "left_shin", "right_thigh", "right_shin", "slider", "wrist", "hand" } },
  };
  for (const Expected& e : expected)
  {
    const LoadedBody& b = loaded(e.fixture);
    std::vector<std::string> links;
    double mass = 0;
    for (const drb::Segment& s : b.body().segments)
    {
      links.push_back(s.link);
      mass += s.inertia.mass;
      EXPECT_TRUE(s.inertia.inertia.allFinite()) << e.fixture << ", segment " << s.link;
    }
    EXPECT_EQ(links, e.segment_links) << e.fixture;
    EXPECT_NEAR(mass, b.body().mass(), 4 * kEps * mass) << e.fixture;
  }
  // The massless wrist segment has no mass of its own but moves the hand.
  const drb::BodyModel& tree = loaded("floating_tree").body();
  const auto wrist = std::find_if(tree.segments.begin(), tree.segments.end(),
                                  [](const drb::Segment& s) { return s.link == "wrist"; });
  ASSERT_NE(wrist, tree.segments.end());
  EXPECT_EQ(wrist->inertia.mass, 0.0);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(tree.coordinates));
  const Eigen::MatrixXd M = massMatrixAt(tree, x.data());
  const int wrist_coordinate = tree.dofs[static_cast<std::size_t>(wrist->first_dof)].coordinate;
  EXPECT_GT(M(wrist_coordinate, wrist_coordinate), 0.0) << "the wrist coordinate must move the hand";
}

TEST(ArticulatedHardCases, HomePosesGivePositiveDefiniteMassMatrices)
{
  struct Home
  {
    const char* fixture;
    std::map<std::string, double> joints;  ///< the rest at 0
  };
  // UR5: all joints 0 (its URDF and this copy give no SRDF). Panda: srdf/panda.srdf "default".
  const std::vector<Home> homes = {
    { "ur5", {} },
    { "panda",
      { { "panda_finger_joint1", 0.001 }, { "panda_joint2", -0.785398 }, { "panda_joint4", -2.35619 },
        { "panda_joint6", 1.5707 }, { "panda_joint7", 0.785398 } } },
    { "double_pendulum", {} },
  };
  for (const Home& home : homes)
  {
    const LoadedBody& b = loaded(home.fixture);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(b.body().coordinates));
    for (const auto& [name, value] : home.joints)
    {
      const auto it = std::find(b.body().joint_names.begin(), b.body().joint_names.end(), name);
      ASSERT_NE(it, b.body().joint_names.end()) << home.fixture << ": " << name;
      x[it - b.body().joint_names.begin()] = value;
    }
    const Eigen::MatrixXd M = massMatrixAt(b.body(), x.data());
    EXPECT_EQ(maxAbs(M - M.transpose()), 0.0) << home.fixture << ": M is not symmetric\n" << M;
    const Eigen::LLT<Eigen::MatrixXd> llt(M);
    EXPECT_EQ(llt.info(), Eigen::Success) << home.fixture << ": Cholesky fails at x = " << row(x) << "\nM =\n" << M;
    const double min_eigenvalue = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff();
    EXPECT_GT(min_eigenvalue, 0.0) << home.fixture << ", x = " << row(x);
    std::printf("[measured] %s home: min eigenvalue of M %.6g kg m^2 (max|M| %.6g)\n", home.fixture, min_eigenvalue,
                maxAbs(M));
  }
}

TEST(ArticulatedHardCases, FreeObjectsLoadInModelModeAsInFreeMode)
{
  // Two floating bodies (a tilted cube with an off-diagonal inertia and a
  // ball) and a floating body with a fixed tool: no joints, so free bodies.
  ub::TwoBodies two;
  two.cube_rpy = "0.3 -0.2 0.1";
  const std::string with_tool =
      ub::robot(ub::link("b", ub::inertial("2", { "0.1", "0.01", "0", "0.2", "0", "0.3" }) +
                                  ub::collision(ub::boxGeometry("0.1 0.2 0.3"))) +
                ub::link("tool", ub::inertial("0.5") + ub::collision(ub::sphereGeometry("0.05"))) +
                ub::floatingJoint("b", "<origin xyz=\"0 0 1\" rpy=\"0 1.2 0\"/>") +
                ub::joint("fixed", "b", "tool", "<origin xyz=\"0.3 0 0\"/>"));
  Random rng(1215);
  for (const std::string& xml : { ub::twoBodies(two), with_tool })
  {
    const drb::Scene model = drb::loadSceneFromUrdf(xml, robotOptions(drb::JointHandling::Model));
    const drb::Scene free = drb::loadSceneFromUrdf(xml, robotOptions(drb::JointHandling::Free));
    ASSERT_EQ(model.bodies.size(), free.bodies.size());
    for (std::size_t i = 0; i < model.bodies.size(); ++i)
    {
      const drb::BodyModel& m = model.bodies[i];
      const drb::BodyModel& f = free.bodies[i];
      const std::string where = "body " + m.name;
      EXPECT_TRUE(m.closedFormKernels()) << where;
      EXPECT_EQ(m.name, f.name);
      EXPECT_EQ(m.coordinates, 6u) << where;
      EXPECT_EQ(m.mass(), f.mass()) << where;
      const Eigen::Matrix3d& m_inertia = m.segments[0].inertia.inertia;
      const Eigen::Matrix3d& f_inertia = f.segments[0].inertia.inertia;
      EXPECT_EQ(maxAbs(m_inertia - f_inertia), 0.0) << where;
      EXPECT_EQ(maxAbs(m.rootComOffset() - f.rootComOffset()), 0.0) << where;
      ASSERT_EQ(m.vertices.cols(), f.vertices.cols()) << where;
      EXPECT_EQ(maxAbs(m.vertices - f.vertices), 0.0) << where;
      ASSERT_EQ(m.initial_x.size(), f.initial_x.size()) << where;
      EXPECT_EQ(maxAbs(m.initial_x - f.initial_x), 0.0) << where;
      for (int s = 0; s < 20; ++s)
      {
        const Vector6<double> q = s == 0 ? Vector6<double>(m.initial_x) : rng.state();
        const Matrix6<double> M_model = drb::massMatrix(q, m.mass(), m_inertia);
        const Matrix6<double> M_free = drb::massMatrix(q, f.mass(), f_inertia);
        ASSERT_EQ(maxAbs(M_model - M_free), 0.0) << where << ", q = " << q.transpose();
      }
    }
  }
}
