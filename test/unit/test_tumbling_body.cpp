// A torque-free asymmetric free body integrated through the node's forward
// dynamics (SceneQueries::forwardDynamics, Euler-angle coordinates), RK4 at
// dt = 1e-3 s, spun about its intermediate principal axis so that it flips
// (the Dzhanibekov effect), under gravity. Independent checks:
//   - the rotational kinetic energy 1/2 w_b . I_b w_b and the world angular
//     momentum R I_b w_b (w_b = A(phi, theta) r') are conserved;
//   - the orientation matches Euler's equations I_b w' = -w x I_b w with
//     R' = R [w]x, integrated by RK4 on a rotation matrix (no Euler angles);
//   - the COM follows t(0) + t'(0) s + gamma s^2 / 2;
//   - the body's intermediate axis turns over (its world z changes sign).
#include <cmath>

#include <gtest/gtest.h>

#include "diff_rigid_body/algorithm/free_body/mass_matrix.h"
#include "diff_rigid_body/multibody/rpy.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "../support/urdf_builders.h"

namespace drb = diff_rigid_body;
using namespace drb_test::urdf;

namespace
{
constexpr double kStep = 1e-3;       // [s]
constexpr double kDuration = 4.0;    // [s]
constexpr double kConservation = 1e-7;  // relative drift of energy and angular momentum
constexpr double kOrientation = 1e-5;   // [rad] between the two integrations
const Eigen::Vector3d kGravity(0.0, 0.0, -9.81);
const Eigen::Vector3d kMoments(1.0, 3.0, 2.0);  // [kg m^2]: z is the intermediate axis

using Vector = Eigen::VectorXd;

/// (x, x') as one vector of 12 and its rate from the node's forward dynamics.
Vector rate(const drb::SceneQueries& queries, const Vector& state)
{
  drb::ForwardDynamicsAnswer answer;
  const std::vector<double> q(state.data(), state.data() + 6), qdot(state.data() + 6, state.data() + 12);
  queries.forwardDynamics(queries.initialState(), {}, q, qdot, {}, false, answer);
  Vector out(12);
  out.head<6>() = state.tail<6>();
  out.tail<6>() = Eigen::Map<const Vector>(answer.qddot.data(), 6);
  return out;
}

template <typename F, typename State>
State rk4(F&& f, const State& y, double h)
{
  const State k1 = f(y), k2 = f(State(y + 0.5 * h * k1)), k3 = f(State(y + 0.5 * h * k2)), k4 = f(State(y + h * k3));
  return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
}

/// Euler's equations on (R, w_b) as one 12-vector (R column-major, then w).
Vector eulerRate(const Vector& y)
{
  const Eigen::Map<const Eigen::Matrix3d> R(y.data());
  const Eigen::Vector3d w = y.tail<3>();
  const Eigen::Vector3d Iw = kMoments.cwiseProduct(w);
  Eigen::Matrix3d W;
  W << 0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0;
  Vector out(12);
  Eigen::Map<Eigen::Matrix3d>(out.data()) = R * W;
  out.tail<3>() = (-w.cross(Iw)).cwiseQuotient(kMoments);
  return out;
}

struct Invariants
{
  double energy;             ///< rotational kinetic energy 1/2 w_b . I_b w_b [J]
  Eigen::Vector3d momentum;  ///< world angular momentum about the COM [kg m^2/s]
};

Invariants invariants(const Vector& state)
{
  const drb::RpyTrig<double> trig(state[0], state[1], state[2]);
  const Eigen::Vector3d w_b = drb::angularVelocityMatrixBody(trig) * state.segment<3>(6);
  const Eigen::Vector3d L_b = kMoments.cwiseProduct(w_b);
  return { 0.5 * w_b.dot(L_b), drb::rpyToMatrix(trig) * L_b };
}
}  // namespace

TEST(TumblingBody, FlipsWhileConservingEnergyAndMomentumAndMatchesEulersEquations)
{
  const std::string urdf = robot(link("handle", inertial("4", { "1", "0", "0", "3", "0", "2" }) +
                                                    collision(boxGeometry("0.3 0.1 0.2"))) +
                                 floatingJoint("handle"));
  const drb::SceneQueries queries(drb::loadSceneFromUrdf(urdf), kGravity);
  const Eigen::Vector3d w0(0.05, 0.02, 4.0);  // [rad/s], body axes: nearly about the intermediate z
  Vector state = Vector::Zero(12);
  state.segment<3>(6) = w0;  // A = I at zero angles
  state.tail<3>() << 0.3, 0.0, 0.5;
  Vector euler(12);
  Eigen::Map<Eigen::Matrix3d>(euler.data()) = Eigen::Matrix3d::Identity();
  euler.tail<3>() = w0;
  const Invariants start = invariants(state);
  double lowest_z = 1.0, worst_angle = 0.0;
  const int steps = static_cast<int>(std::lround(kDuration / kStep));
  for (int n = 1; n <= steps; ++n)
  {
    state = rk4([&](const Vector& y) { return rate(queries, y); }, state, kStep);
    euler = rk4(eulerRate, euler, kStep);
    const Eigen::Matrix3d R = drb::rpyToMatrix(drb::RpyTrig<double>(state[0], state[1], state[2]));
    const Eigen::Map<const Eigen::Matrix3d> R_euler(euler.data());
    worst_angle = std::max(worst_angle, Eigen::AngleAxisd(R.transpose() * R_euler).angle());
    lowest_z = std::min(lowest_z, R(2, 2));
  }
  const Invariants end = invariants(state);
  EXPECT_LT(std::abs(end.energy - start.energy) / start.energy, kConservation);
  EXPECT_LT((end.momentum - start.momentum).norm() / start.momentum.norm(), kConservation);
  EXPECT_LT(worst_angle, kOrientation) << "orientation against Euler's equations on a rotation matrix";
  EXPECT_LT(lowest_z, -0.9) << "the intermediate axis should turn over (Dzhanibekov)";
  const Eigen::Vector3d t = Eigen::Vector3d(0.3, 0.0, 0.5) * kDuration + 0.5 * kGravity * kDuration * kDuration;
  EXPECT_LT((state.segment<3>(3) - t).norm(), 1e-9) << "COM under gravity alone";
}
