// Frame and centre-of-mass Jacobians against KDL and MuJoCo loading the same
// URDFs (Pinocchio's are in test_dynamics_pinocchio.cpp).
//   KDL (kdl_parser's tree, getChain from the body's static base link to the
//   fixture's tip): ChainJntToJacSolver (the tip's Jacobian: its origin's
//   velocity and the angular velocity, in the chain base's axes, i.e.
//   LOCAL_WORLD_ALIGNED rotated by the base's pose) and
//   ChainJntToJacDotSolver in its hybrid representation (J'x', the same
//   reference) on the chain fixtures.
//   MuJoCo (mujoco_model.h): mj_jacBody (a body's origin, world axes) for
//   every link MuJoCo keeps, and mj_jacSubtreeCom with subtree_com for the
//   body's centre of mass, on the Panda and the UR5. MuJoCo ignores
//   <mimic>: our coordinate c drives its joint j as q_j = A(j, c) x_c + o_j,
//   so our Jacobian is MuJoCo's times A.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>
#include <kdl/chainjnttojacdotsolver.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include "diff_rigid_body/services/scene_queries.h"
#include "../support/dynamics_fixtures.h"
#include "../support/peer_joints.h"
#include "../support/mujoco_model.h"

namespace drb = diff_rigid_body;
using drb_test::dynamics::dynamicsBodies;
using drb_test::dynamics::relativeDifference;

namespace
{
constexpr double kAgreement = 1e-12;  // relative: two double implementations of kinematics
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

using drb_test::peers::coordinateOf;
using drb_test::peers::fixture;
using drb_test::peers::spec;

/// Our answer for `frames` of the fixture's body at one configuration.
drb::FrameJacobianAnswer ourFrames(const drb_test::dynamics::DynamicsBody& f, const std::vector<std::string>& frames,
                                   const Vector& x, const Vector& xd)
{
  const drb::SceneQueries queries(f.scene);
  drb::FrameJacobianAnswer answer;
  queries.frameJacobians(queries.initialState(), f.model().name, frames, std::vector<double>(x.data(), x.data() + x.size()),
                         std::vector<double>(xd.data(), xd.data() + xd.size()), 2, true, answer);
  return answer;
}

class KdlFrames : public ::testing::TestWithParam<const char*>
{
};

class MujocoFrames : public ::testing::TestWithParam<const char*>
{
};
}  // namespace

TEST_P(KdlFrames, TipJacobianAndItsRate)
{
  const auto& f = fixture(GetParam());
  const drb::BodyModel& model = f.model();
  const std::string tip = spec(f.name).tip;
  const drb_test::peers::KdlChain kdl = drb_test::peers::kdlChain(f);
  const KDL::Chain& chain = kdl.chain;
  Matrix rotate = Matrix::Zero(6, 6);  // KDL answers in the chain base's axes
  rotate.topLeftCorner(3, 3) = rotate.bottomRightCorner(3, 3) = kdl.R_base;
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  std::mt19937_64 rng(29);
  for (int trial = 0; trial < 3; ++trial)
  {
    const auto m = drb_test::dynamics::randomMotion(model, rng);
    const unsigned n = chain.getNrOfJoints();
    KDL::JntArray q(n), qd(n);
    Matrix A = Matrix::Zero(n, d);  // KDL's joint rates = A x'
    unsigned k = 0;
    for (const KDL::Segment& segment : chain.segments)
    {
      if (segment.getJoint().getType() == KDL::Joint::None)
        continue;
      int c = -1;
      double multiplier = 1, offset = 0;
      ASSERT_TRUE(coordinateOf(model, segment.getJoint().getName(), c, multiplier, offset));
      q(k) = multiplier * m.x[c] + offset;
      qd(k) = multiplier * m.xd[c];
      A(k++, c) = multiplier;
    }
    KDL::Jacobian jacobian(n);
    ASSERT_GE(KDL::ChainJntToJacSolver(chain).JntToJac(q, jacobian), 0);
    KDL::ChainJntToJacDotSolver rate_solver(chain);
    rate_solver.setHybridRepresentation();
    KDL::Twist bias;
    ASSERT_GE(rate_solver.JntToJacDot(KDL::JntArrayVel(q, qd), bias), 0);
    const auto ours = ourFrames(f, { tip }, m.x, m.xd);
    const Matrix J = Eigen::Map<const RowMajor>(ours.jacobians.data(), 6, d);
    EXPECT_LT(relativeDifference(J, rotate * jacobian.data * A), kAgreement) << f.name << ": ChainJntToJacSolver";
    Vector bias_kdl(6);
    bias_kdl << bias.vel.x(), bias.vel.y(), bias.vel.z(), bias.rot.x(), bias.rot.y(), bias.rot.z();
    EXPECT_LT(relativeDifference(Eigen::Map<const Vector>(ours.acceleration_bias.data(), 6), rotate * bias_kdl),
              kAgreement)
        << f.name << ": ChainJntToJacDotSolver";
  }
}

TEST_P(MujocoFrames, BodyJacobiansAndSubtreeCom)
{
  const auto& f = fixture(GetParam());
  const drb::BodyModel& model = f.model();
  drb_test::mujoco::Model mj(drb_test::articulated::readText(spec(f.name).path));
  const mjModel& mm = mj.model();
  mjData& data = mj.data();
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  const drb_test::peers::MujocoJoints joints = drb_test::peers::mujocoJoints(mm, model);
  const Matrix& A = joints.A;
  const std::vector<int>& qpos_of = joints.qpos_of;
  std::vector<std::string> kept;  // our links that MuJoCo keeps as bodies (fusestatic merges the others)
  for (const drb::LinkInBody& link : model.links)
    if (mj.body(link.name) >= 0)
      kept.push_back(link.name);
  ASSERT_GE(kept.size(), 6u);
  std::mt19937_64 rng(31);
  RowMajor jacp(3, mm.nv), jacr(3, mm.nv);
  for (int trial = 0; trial < 3; ++trial)
  {
    const auto m = drb_test::dynamics::randomMotion(model, rng);
    const Vector q = A * m.x + joints.offset;
    for (int i = 0; i < mm.nv; ++i)
      data.qpos[qpos_of[std::size_t(i)]] = q[i];
    mj_kinematics(&mm, &data);
    mj_comPos(&mm, &data);
    const auto ours = ourFrames(f, kept, m.x, Vector::Zero(d));
    for (std::size_t l = 0; l < kept.size(); ++l)
    {
      mj_jacBody(&mm, &data, jacp.data(), jacr.data(), mj.body(kept[l]));
      Matrix J_mj(6, mm.nv);
      J_mj << jacp, jacr;
      const Matrix J = Eigen::Map<const RowMajor>(ours.jacobians.data() + 6 * d * l, 6, d);
      EXPECT_LT(relativeDifference(J, J_mj * A), kAgreement) << f.name << ": mj_jacBody of " << kept[l];
    }
    const int root = mj.body(model.name);
    ASSERT_GE(root, 0);
    mj_jacSubtreeCom(&mm, &data, jacp.data(), root);
    const drb::SceneQueries queries(f.scene);
    drb::CenterOfMassAnswer com;
    queries.centerOfMass(queries.initialState(), { model.name }, std::vector<double>(m.x.data(), m.x.data() + d), {},
                         true, com);
    EXPECT_LT(relativeDifference(Eigen::Map<const Vector>(com.com.data(), 3),
                                 Eigen::Map<const Vector>(data.subtree_com + 3 * root, 3)),
              kAgreement)
        << f.name << ": subtree_com";
    EXPECT_LT(relativeDifference(Eigen::Map<const RowMajor>(com.jacobians.data(), 3, d), Matrix(jacp * A)), kAgreement)
        << f.name << ": mj_jacSubtreeCom";
  }
}

TEST(FramePaths, ASubsetWithoutBiasHasTheBitsOfFullKinematics)
{
  // Without the bias a request places only its frames' paths
  // (forwardKinematicsOf): after a request for other frames on the same
  // thread, no entry it reads may be stale.
  for (const char* name : { "panda", "floating_humanoid" })
  {
    const auto& f = fixture(name);
    const drb::BodyModel& model = f.model();
    const drb::SceneQueries queries(f.scene);
    std::mt19937_64 rng(37);
    const auto m = drb_test::dynamics::randomMotion(model, rng), elsewhere = drb_test::dynamics::randomMotion(model, rng);
    const std::vector<double> x(m.x.data(), m.x.data() + m.x.size());
    const std::vector<double> x2(elsewhere.x.data(), elsewhere.x.data() + elsewhere.x.size());
    const std::size_t last = model.links.size() - 1, middle = model.links.size() / 2;
    const std::vector<std::string> subset{ model.links[1].name, model.links[middle].name };
    drb::FrameJacobianAnswer full, other, partial;
    queries.frameJacobians(queries.initialState(), model.name, {}, x, {}, 0, true, full);
    // Every segment of this thread's workspace at another configuration x2,
    // so that an entry the subset's request leaves unplaced would differ.
    queries.frameJacobians(queries.initialState(), model.name, {}, x2, {}, 0, true, other);
    queries.frameJacobians(queries.initialState(), model.name, { model.links[last].name }, x2, {}, 0, false, other);
    queries.frameJacobians(queries.initialState(), model.name, subset, x, {}, 0, false, partial);
    const std::size_t d = model.coordinates;
    for (std::size_t k = 0; k < subset.size(); ++k)
    {
      const std::size_t l = k == 0 ? 1 : middle;
      EXPECT_TRUE(std::equal(partial.poses.begin() + 12 * k, partial.poses.begin() + 12 * (k + 1),
                             full.poses.begin() + 12 * l))
          << name << ": pose of " << subset[k];
      EXPECT_TRUE(std::equal(partial.jacobians.begin() + 6 * d * k, partial.jacobians.begin() + 6 * d * (k + 1),
                             full.jacobians.begin() + 6 * d * l))
          << name << ": J of " << subset[k];
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Chains, KdlFrames,
                         ::testing::Values("ur5", "double_pendulum", "double_pendulum_continuous", "double_pendulum_simple"));
INSTANTIATE_TEST_SUITE_P(Robots, MujocoFrames, ::testing::Values("panda", "ur5"));
