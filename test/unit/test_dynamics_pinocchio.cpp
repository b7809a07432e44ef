// The equations of motion against Pinocchio 3.7.0 (bench/pinocchio_peer.h)
// loading the same URDFs: rnea, computeGeneralizedGravity,
// computeCoriolisMatrix, computeRNEADerivatives, aba and
// computeABADerivatives, on every dynamics fixture. A free root is
// Pinocchio's Translation + RZ + RY + RX chain placed at the COM
// (PinocchioRoot::EulerZYX): our free body, with (tx, ty, tz, psi, theta, phi)
// a permutation of our (phi, theta, psi, tx, ty, tz). Pinocchio ignores
// <mimic>, so our coordinate c drives its joint j as q_j = A(j, c) x_c + o_j,
// and everything maps with A: tau = A^T tau_p, C = A^T C_p A, dtau/dx =
// A^T dtau_p/dq A. Its aba (independent joints only) is compared where A is
// a permutation; with a mimic joint, x'' from its M and bias instead.
#include <cstdio>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "pinocchio_peer.h"
#include "../support/dynamics_fixtures.h"

namespace drb = diff_rigid_body;
using drb_pinocchio::PinocchioRobot;
using drb_pinocchio::PinocchioRoot;
using drb_test::dynamics::dynamicsBodies;
using drb_test::dynamics::relativeDifference;

namespace
{
constexpr double kAgreement = 1e-11;  // relative: two double implementations
const Eigen::Vector3d kGravity(0.4, -0.3, -9.81);
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

/// The fixture's URDF as a file Pinocchio can read.
std::string urdfFile(const std::string& name)
{
  for (const auto& f : drb_test::articulated::fixedBaseFixtures())
    if (name == f.name)
      return f.path;
  const std::string path = "/tmp/drb_pinocchio_" + name + ".urdf";
  std::ofstream(path) << (name == "floating_tree"     ? drb_test::articulated::floatingTreeUrdf() :
                          name == "floating_humanoid" ? drb_test::dynamics::floatingHumanoidUrdf() :
                                                        drb_test::dynamics::asymmetricFreeBodyUrdf());
  return path;
}

/// Pinocchio's joint velocities from ours: v_p = A x', q_p = A x + o.
struct CoordinateMap
{
  Matrix A;
  Vector offset;
};

CoordinateMap coordinateMap(const drb::BodyModel& model, const PinocchioRobot& robot)
{
  CoordinateMap map{ Matrix::Zero(robot.nv(), static_cast<Eigen::Index>(model.coordinates)), Vector::Zero(robot.nv()) };
  for (const auto& joint : robot.joints())
  {
    if (joint.name.find("_translation") != std::string::npos)
    {
      for (int k = 0; k < 3; ++k)
        map.A(joint.idx_v + k, drb::TX + k) = 1.0;
      continue;
    }
    const auto ends = [&](const char* suffix) {
      const std::string s(suffix);
      return joint.name.size() > s.size() && joint.name.compare(joint.name.size() - s.size(), s.size(), s) == 0;
    };
    if (ends("_rz") || ends("_ry") || ends("_rx"))
    {
      map.A(joint.idx_v, ends("_rz") ? drb::PSI : ends("_ry") ? drb::THETA : drb::PHI) = 1.0;
      continue;
    }
    for (const drb::Segment& segment : model.segments)
      if (segment.joint == joint.name && segment.joint_type != drb::JointType::Free)
      {
        const drb::Dof& dof = model.dofs[static_cast<std::size_t>(segment.first_dof)];
        map.A(joint.idx_v, dof.coordinate) = dof.multiplier;
        map.offset[joint.idx_v] = segment.offset;
      }
  }
  return map;
}

class DynamicsPinocchio : public ::testing::TestWithParam<std::size_t>
{
protected:
  DynamicsPinocchio()
    : fixture_(dynamicsBodies()[GetParam()])
    , robot_(urdfFile(fixture_.name),
             fixture_.model().hasFreeRoot() ? PinocchioRoot::EulerZYX : PinocchioRoot::Fixed)
    , map_(coordinateMap(fixture_.model(), robot_))
  {
    robot_.setGravity(kGravity);
  }

  const drb::BodyModel& model() const { return fixture_.model(); }
  /// The A of the map is a permutation: one Pinocchio joint per coordinate, no mimic.
  bool permutation() const { return map_.A.rows() == map_.A.cols() && (map_.A.cwiseAbs().colwise().sum().array() == 1).all(); }

  const drb_test::dynamics::DynamicsBody& fixture_;
  PinocchioRobot robot_;
  CoordinateMap map_;
};
}  // namespace

TEST_P(DynamicsPinocchio, InverseDynamicsCoriolisGravityAndDerivatives)
{
  std::mt19937_64 rng(7 + GetParam());
  const Eigen::Index d = static_cast<Eigen::Index>(model().coordinates);
  ASSERT_EQ(map_.A.colwise().squaredNorm().minCoeff() > 0, true) << "a coordinate Pinocchio does not have";
  for (int trial = 0; trial < 2; ++trial)
  {
    const auto m = drb_test::dynamics::randomMotion(model(), rng);
    const Vector q = robot_.configuration(map_.A * m.x + map_.offset), v = map_.A * m.xd, a = map_.A * m.xdd;
    const Vector tau_p = robot_.rnea(q, v, a);
    const Vector g_p = robot_.generalizedGravity(q);
    const Matrix C_p = robot_.coriolisMatrix(q, v);
    const auto derivatives = robot_.rneaDerivatives(q, v, a);
    const Matrix dq_p = derivatives.dtau_dq, dv_p = derivatives.dtau_dv;

    drb::BodyWorkspace<double> ws(model());
    Vector tau(d), g(d);
    Matrix dq(d, d), dv(d, d);
    drb::inverseDynamics(model(), ws, m.x.data(), m.xd.data(), m.xdd.data(), kGravity, tau.data());
    drb::inverseDynamics(model(), ws, m.x.data(), static_cast<const double*>(nullptr),
                         static_cast<const double*>(nullptr), kGravity, g.data());
    drb::inverseDynamicsDerivatives(model(), ws, m.x.data(), m.xd.data(), m.xdd.data(), kGravity, dq, dv);
    const Matrix& A = map_.A;
    EXPECT_LT(relativeDifference(tau, A.transpose() * tau_p), kAgreement) << fixture_.name << ": rnea";
    EXPECT_LT(relativeDifference(g, A.transpose() * g_p), kAgreement) << fixture_.name << ": gravity";
    EXPECT_LT(relativeDifference(0.5 * dv, A.transpose() * C_p * A), kAgreement) << fixture_.name << ": C";
    EXPECT_LT(relativeDifference(dq, A.transpose() * dq_p * A), kAgreement) << fixture_.name << ": dtau/dq";
    EXPECT_LT(relativeDifference(dv, A.transpose() * dv_p * A), kAgreement) << fixture_.name << ": dtau/dv";
  }
}

TEST_P(DynamicsPinocchio, ForwardDynamicsAndDerivatives)
{
  std::mt19937_64 rng(11 + GetParam());
  const Eigen::Index d = static_cast<Eigen::Index>(model().coordinates);
  for (int trial = 0; trial < 2; ++trial)
  {
    const auto m = drb_test::dynamics::randomMotion(model(), rng);
    const Vector q = robot_.configuration(map_.A * m.x + map_.offset), v = map_.A * m.xd;
    drb::BodyWorkspace<double> ws(model());
    Vector xdd(d);
    Matrix dq(d, d), dv(d, d), inverse_mass(d, d);
    ASSERT_EQ(drb::forwardDynamicsDerivatives(model(), ws, m.x.data(), m.xd.data(), m.tau.data(), kGravity, xdd.data(),
                                              dq, dv, inverse_mass),
              -1);
    const Matrix& A = map_.A;
    if (!permutation())
    {
      // Mimic: x'' = (A^T M_p A)^-1 (tau - A^T b_p), b_p = rnea(q, v, 0).
      const Matrix M = A.transpose() * robot_.crba(q) * A;
      const Vector bias = A.transpose() * robot_.rnea(q, v, Vector::Zero(robot_.nv()));
      EXPECT_LT(relativeDifference(xdd, M.ldlt().solve(m.tau - bias)), kAgreement) << fixture_.name;
      continue;
    }
    const Vector xdd_p = robot_.aba(q, v, A * m.tau);  // A orthogonal: tau_p = A tau
    const auto derivatives = robot_.abaDerivatives(q, v, A * m.tau);
    EXPECT_LT(relativeDifference(xdd, A.transpose() * xdd_p), kAgreement) << fixture_.name << ": aba";
    EXPECT_LT(relativeDifference(dq, A.transpose() * Matrix(derivatives.ddq_dq) * A), kAgreement) << fixture_.name;
    EXPECT_LT(relativeDifference(dv, A.transpose() * Matrix(derivatives.ddq_dv) * A), kAgreement) << fixture_.name;
    EXPECT_LT(relativeDifference(inverse_mass, A.transpose() * Matrix(derivatives.Minv) * A), kAgreement)
        << fixture_.name;
  }
}

TEST_P(DynamicsPinocchio, FrameJacobiansAndCenterOfMass)
{
  // Every link frame in the three references (J and the classical
  // acceleration at x'' = 0) and the body's COM (its subtree in Pinocchio),
  // through SceneQueries as the node serves them.
  std::mt19937_64 rng(13 + GetParam());
  const drb::SceneQueries queries(fixture_.scene);
  const Eigen::Index d = static_cast<Eigen::Index>(model().coordinates);
  const Matrix& A = map_.A;
  const auto m = drb_test::dynamics::randomMotion(model(), rng);
  const Vector q = robot_.configuration(A * m.x + map_.offset), v = A * m.xd;
  const std::vector<double> x(m.x.data(), m.x.data() + d), xd(m.xd.data(), m.xd.data() + d);
  for (std::uint32_t reference = 0; reference < 3; ++reference)
  {
    drb::FrameJacobianAnswer answer;
    queries.frameJacobians(queries.initialState(), model().name, {}, x, xd, reference, true, answer);
    ASSERT_EQ(answer.frames.size(), model().links.size());
    for (std::size_t f = 0; f < answer.frames.size(); ++f)
    {
      const auto peer = robot_.frameJacobian(q, v, answer.frames[f], static_cast<int>(reference));
      const Matrix J = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          answer.jacobians.data() + 6 * d * static_cast<Eigen::Index>(f), 6, d);
      const std::string at = fixture_.name + ": frame " + answer.frames[f] + ", reference " + std::to_string(reference);
      EXPECT_LT(relativeDifference(J, Matrix(peer.J * A)), kAgreement) << at;
      EXPECT_LT(relativeDifference(Eigen::Map<const Vector>(answer.acceleration_bias.data() + 6 * f, 6),
                                   Vector(peer.classical)),
                kAgreement)
          << at;
    }
  }
  const std::string root_joint = model().hasFreeRoot() ? model().joint_name + "_translation" : model().segments[0].joint;
  const auto peer = robot_.centerOfMass(q, v, root_joint);
  drb::CenterOfMassAnswer com;
  queries.centerOfMass(queries.initialState(), { model().name }, x, xd, true, com);
  EXPECT_LT(relativeDifference(Eigen::Map<const Vector>(com.com.data(), 3), Vector(peer.com)), kAgreement);
  EXPECT_LT(relativeDifference(Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                                   com.jacobians.data(), 3, d),
                               Matrix(peer.J * A)),
            kAgreement)
      << fixture_.name << ": COM Jacobian";
  // A free body's COM is its (tx, ty, tz): J'x' = 0, so the scale is 1 m/s^2.
  const Vector acceleration_error = Eigen::Map<const Vector>(com.acceleration_bias.data(), 3) - peer.acceleration;
  EXPECT_LT(acceleration_error.cwiseAbs().maxCoeff(), kAgreement * std::max(1.0, peer.acceleration.norm()))
      << fixture_.name << ": COM acceleration";
}

INSTANTIATE_TEST_SUITE_P(Bodies, DynamicsPinocchio, ::testing::Range<std::size_t>(0, dynamicsBodies().size()),
                         [](const ::testing::TestParamInfo<std::size_t>& info) {
                           return dynamicsBodies()[info.param].name;
                         });
