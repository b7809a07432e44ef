// The equations of motion against KDL and MuJoCo loading the same URDFs.
//   KDL (kdl_parser's tree, getChain from the body's static base link to a
//   tip): ChainIdSolver_RNE (tau), ChainDynParam::JntToCoriolis (c) and
//   JntToGravity (g) on the fixed-base chain fixtures whose chain carries
//   every coordinate of the body (the UR5, the double pendulums). Gravity
//   goes to KDL in the chain base's axes.
//   MuJoCo (mujoco_model.h, damping and armature cleared): mj_inverse (tau),
//   mj_rne without acceleration (c + g) and mj_forward (x'') on the Panda
//   and the UR5. MuJoCo and KDL ignore <mimic>: our coordinate c drives
//   their joint j as q_j = A(j, c) x_c + o_j, so tau = A^T tau_peer; where
//   A is not a permutation (the Panda's finger), x'' is compared through
//   MuJoCo's M and bias.
// (The floating tree's free root is checked against Pinocchio's
// Euler-angle chain in test_dynamics_pinocchio.cpp.)
#include <random>

#include <gtest/gtest.h>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "../support/dynamics_fixtures.h"
#include "../support/peer_joints.h"
#include "../support/mujoco_model.h"

namespace drb = diff_rigid_body;
using drb_test::dynamics::dynamicsBodies;
using drb_test::dynamics::relativeDifference;

namespace
{
constexpr double kAgreement = 1e-11;  // relative: two double implementations
// MuJoCo replaces a full inertia tensor by principal moments and axes from
// an iterative eigen-solver (test_articulated_mujoco.cpp: 1.4e-10 of max|M|
// on full tensors); the Panda's are full, so its terms agree to ~1e-9.
constexpr double kMujocoAgreement = 1e-8;
const Eigen::Vector3d kGravity(0.4, -0.3, -9.81);
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

using drb_test::peers::coordinateOf;
using drb_test::peers::fixture;
using drb_test::peers::spec;

struct OurTerms
{
  Vector tau, c, g;
};

OurTerms ourTerms(const drb::BodyModel& model, const drb_test::dynamics::Motion& m)
{
  drb::BodyWorkspace<double> ws(model);
  const Eigen::Index d = m.x.size();
  OurTerms out{ Vector(d), Vector(d), Vector(d) };
  drb::inverseDynamics(model, ws, m.x.data(), m.xd.data(), m.xdd.data(), kGravity, out.tau.data());
  drb::inverseDynamics(model, ws, m.x.data(), m.xd.data(), static_cast<const double*>(nullptr),
                       drb::Vector3<double>::Zero().eval(), out.c.data());
  drb::inverseDynamics(model, ws, m.x.data(), static_cast<const double*>(nullptr),
                       static_cast<const double*>(nullptr), kGravity, out.g.data());
  return out;
}

class KdlChains : public ::testing::TestWithParam<const char*>
{
};

class MujocoRobots : public ::testing::TestWithParam<const char*>
{
};
}  // namespace

TEST_P(KdlChains, RneCoriolisAndGravity)
{
  const auto& f = fixture(GetParam());
  const drb::BodyModel& model = f.model();
  const drb_test::peers::KdlChain kdl = drb_test::peers::kdlChain(f);
  const KDL::Chain& chain = kdl.chain;
  ASSERT_EQ(chain.getNrOfJoints(), model.coordinates) << "the chain must carry every coordinate";
  // Gravity in the chain base's axes: the base is a static link, posed in the fixed frame.
  const Eigen::Vector3d g_base = kdl.R_base.transpose() * kGravity;
  const KDL::Vector gravity(g_base[0], g_base[1], g_base[2]);
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 3; ++trial)
  {
    const auto m = drb_test::dynamics::randomMotion(model, rng);
    const unsigned n = chain.getNrOfJoints();
    KDL::JntArray q(n), qd(n), qdd(n), tau(n), coriolis(n), gravity_torque(n);
    std::vector<int> column;
    for (const KDL::Segment& segment : chain.segments)
    {
      if (segment.getJoint().getType() == KDL::Joint::None)
        continue;
      int c = -1;
      double multiplier = 1, offset = 0;
      ASSERT_TRUE(coordinateOf(model, segment.getJoint().getName(), c, multiplier, offset));
      const unsigned k = static_cast<unsigned>(column.size());
      q(k) = m.x[c];
      qd(k) = m.xd[c];
      qdd(k) = m.xdd[c];
      column.push_back(c);
    }
    KDL::ChainIdSolver_RNE rne(chain, gravity);
    KDL::Wrenches external(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(rne.CartToJnt(q, qd, qdd, external, tau), 0);
    KDL::ChainDynParam parameters(chain, gravity);
    ASSERT_GE(parameters.JntToCoriolis(q, qd, coriolis), 0);
    ASSERT_GE(parameters.JntToGravity(q, gravity_torque), 0);
    Vector tau_kdl(n), c_kdl(n), g_kdl(n);
    for (unsigned k = 0; k < n; ++k)
    {
      tau_kdl[column[k]] = tau(k);
      c_kdl[column[k]] = coriolis(k);
      g_kdl[column[k]] = gravity_torque(k);
    }
    const OurTerms ours = ourTerms(model, m);
    EXPECT_LT(relativeDifference(ours.tau, tau_kdl), kAgreement) << f.name << ": ChainIdSolver_RNE";
    EXPECT_LT(relativeDifference(ours.c, c_kdl), kAgreement) << f.name << ": JntToCoriolis";
    EXPECT_LT(relativeDifference(ours.g, g_kdl), kAgreement) << f.name << ": JntToGravity";
  }
}

TEST_P(MujocoRobots, InverseAndForwardDynamics)
{
  const auto& f = fixture(GetParam());
  const drb::BodyModel& model = f.model();
  drb_test::mujoco::Model mj(drb_test::articulated::readText(spec(f.name).path));
  mjModel& mm = mj.mutableModel();
  for (int k = 0; k < 3; ++k)
    mm.opt.gravity[k] = kGravity[k];
  for (int i = 0; i < mm.nv; ++i)
    mm.dof_damping[i] = mm.dof_armature[i] = mm.dof_frictionloss[i] = 0;
  mm.opt.disableflags |= mjDSBL_CONSTRAINT;  // the Panda's joint limits would add constraint forces
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  const drb_test::peers::MujocoJoints joints = drb_test::peers::mujocoJoints(mm, model);
  const Matrix& A = joints.A;
  const Vector& offset = joints.offset;
  const std::vector<int>& qpos_of = joints.qpos_of;
  std::mt19937_64 rng(5);
  mjData& data = mj.data();
  for (int trial = 0; trial < 3; ++trial)
  {
    const auto m = drb_test::dynamics::randomMotion(model, rng);
    const Vector q = A * m.x + offset, v = A * m.xd, a = A * m.xdd;
    for (int i = 0; i < mm.nv; ++i)
    {
      data.qpos[qpos_of[std::size_t(i)]] = q[i];
      data.qvel[i] = v[i];
      data.qacc[i] = a[i];
    }
    mj_inverse(&mm, &data);
    const Vector tau_mj = Eigen::Map<const Vector>(data.qfrc_inverse, mm.nv);
    const Vector bias_mj = Eigen::Map<const Vector>(data.qfrc_bias, mm.nv);  // c + g
    const OurTerms ours = ourTerms(model, m);
    EXPECT_LT(relativeDifference(ours.tau, A.transpose() * tau_mj), kMujocoAgreement) << f.name << ": mj_inverse";
    EXPECT_LT(relativeDifference(ours.c + ours.g, A.transpose() * bias_mj), kMujocoAgreement) << f.name << ": mj_rne";
    // Forward dynamics: x'' for a random tau, against MuJoCo's M and bias in our coordinates.
    std::vector<double> dense(static_cast<std::size_t>(mm.nv * mm.nv));
    mj_fullM(&mm, dense.data(), data.qM);
    const Matrix M_mj = A.transpose() *
                        Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(dense.data(), mm.nv, mm.nv) * A;
    drb::BodyWorkspace<double> ws(model);
    Vector xdd(d);
    ASSERT_EQ(drb::forwardDynamics(model, ws, m.x.data(), m.xd.data(), m.tau.data(), kGravity, xdd.data()), -1);
    // x'' carries cond(M) (the Panda's fingers weigh 15 g): 1e-6 relative.
    EXPECT_LT(relativeDifference(xdd, M_mj.ldlt().solve(m.tau - A.transpose() * bias_mj)), 1e-6) << f.name;
    if (A.rows() == A.cols())  // no mimic: MuJoCo's own forward dynamics
    {
      const Vector tau_mj_space = A * m.tau;  // A is a permutation here
      for (int i = 0; i < mm.nv; ++i)
        data.qfrc_applied[i] = tau_mj_space[i];
      mj_forward(&mm, &data);
      EXPECT_LT(relativeDifference(xdd, A.transpose() * Eigen::Map<const Vector>(data.qacc, mm.nv)), 1e-6)
          << f.name << ": mj_forward";
      for (int i = 0; i < mm.nv; ++i)
        data.qfrc_applied[i] = 0;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Chains, KdlChains,
                         ::testing::Values("ur5", "double_pendulum", "double_pendulum_continuous", "double_pendulum_simple"));
INSTANTIATE_TEST_SUITE_P(Robots, MujocoRobots, ::testing::Values("panda", "ur5"));
