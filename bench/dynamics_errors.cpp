// Inverse and forward dynamics and their derivatives against MPFR
// (body_errors.h), gravity gamma = (0, 0, -9.81) m/s^2, keys
//   tau.{ours, kdl, mujoco, pinocchio}        tau = M x'' + c + g
//   dtau_dx.{ours, pinocchio}, dtau_dxd.{ours, pinocchio}
//   fd.{ours, pinocchio}                      x'' = M^-1 (tau - c - g)
//   dfd_dx.{ours, pinocchio}, dfd_dxd.{ours, pinocchio}, minv.{ours, pinocchio}
// (tau.kdl against the reference of the mass KDL's chain covers). The
// derivatives on every 8th error state (ID) and every 16th (FD: each
// reference column is two mpreal forward dynamics).
#include "body_errors.h"

#include "mpfr_reference.h"
#include "robot_peers.h"

namespace drb_bench
{
namespace
{
const Eigen::Vector3d kGravity = drb::standardGravity();

MatrixMp column(const VectorX<mpreal>& v)
{
  return MatrixMp(v);
}

void peerTauErrors(const Robot& robot, const RobotState& s, const MatrixMp& ref, ErrorTable& table)
{
  RobotPeers& peers = peersOf(robot);
  (void)peers, (void)s, (void)ref, (void)table;
  const std::size_t d = robot.coordinates;
  (void)d;
#ifdef DRB_BENCH_HAVE_KDL_PARSER
  if (!robot.floating)
  {
    KdlArm& kdl = *peers.kdl;
    const std::vector<drb::BodyModel> on_chain = massOnlyIn(robot.bodies(), kdl.links);
    const RobotModel chain{ on_chain, robot.offsets, d };
    const MatrixMp ref_chain = column(robotInverseDynamics(chain, toScalar<mpreal>(s.x), toScalar<mpreal>(s.xd),
                                                           toScalar<mpreal>(s.xdd), kGravity));
    kdl.inverseDynamics(s.x.data(), s.xd.data(), s.xdd.data());
    recordMax(table, "tau.kdl", relativeError(Eigen::MatrixXd(kdl.tauInCoordinates(d)), ref_chain));
  }
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  if (!peers.mujoco->has_free_joint)
  {
    peers.mujoco->inverseDynamics(s.x.data(), s.xd.data(), s.xdd.data());
    recordMax(table, "tau.mujoco", relativeError(Eigen::MatrixXd(peers.mujoco->tauInCoordinates(d)), ref));
  }
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm& pin = peers.pinocchioOracle();
  const Eigen::VectorXd tau =
      pin.A.transpose() * pin.model.rnea(pin.configuration(s.x.data()), pin.velocity(s.xd.data()),
                                         pin.velocity(s.xdd.data()));
  recordMax(table, "tau.pinocchio", relativeError(Eigen::MatrixXd(tau), ref));
#endif
}

void peerForwardDynamicsErrors(const Robot& robot, const RobotState& s, const MatrixMp& ref, ErrorTable& table)
{
  (void)robot, (void)s, (void)ref, (void)table;
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm& pin = peersOf(robot).pinocchioOracle();
  if (!pin.permutation())
    return;
  const Eigen::VectorXd xdd = pin.A.transpose() * pin.model.aba(pin.configuration(s.x.data()),
                                                                pin.velocity(s.xd.data()), pin.velocity(s.tau.data()));
  recordMax(table, "fd.pinocchio", relativeError(Eigen::MatrixXd(xdd), ref));
#endif
}

void inverseDynamicsDerivativeErrors(const Robot& robot, const RobotState& s, ErrorTable& table)
{
  const RobotModel model = modelOf(robot);
  const std::vector<mpreal> x = toScalar<mpreal>(s.x), xd = toScalar<mpreal>(s.xd), xdd = toScalar<mpreal>(s.xdd);
  const MatrixMp by_x = jacobianFrom(centralDifferences(
      s.x, [&](const std::vector<mpreal>& at) { return column(robotInverseDynamics(model, at, xd, xdd, kGravity)); }));
  const MatrixMp by_xd = jacobianFrom(centralDifferences(
      s.xd, [&](const std::vector<mpreal>& at) { return column(robotInverseDynamics(model, x, at, xdd, kGravity)); }));
  const Derivatives ours = robotInverseDynamicsDerivatives(model, s, kGravity);
  recordMax(table, "dtau_dx.ours", relativeError(ours.by_x, by_x));
  recordMax(table, "dtau_dxd.ours", relativeError(ours.by_xd, by_xd));
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm& pin = peersOf(robot).pinocchioOracle();
  const auto peer = pin.model.rneaDerivatives(pin.configuration(s.x.data()), pin.velocity(s.xd.data()),
                                              pin.velocity(s.xdd.data()));
  recordMax(table, "dtau_dx.pinocchio", relativeError(Eigen::MatrixXd(pin.A.transpose() * peer.dtau_dq * pin.A), by_x));
  recordMax(table, "dtau_dxd.pinocchio", relativeError(Eigen::MatrixXd(pin.A.transpose() * peer.dtau_dv * pin.A), by_xd));
#endif
}

void forwardDynamicsDerivativeErrors(const Robot& robot, const RobotState& s, ErrorTable& table)
{
  const RobotModel model = modelOf(robot);
  const std::vector<mpreal> x = toScalar<mpreal>(s.x), xd = toScalar<mpreal>(s.xd), tau = toScalar<mpreal>(s.tau);
  const MatrixMp by_x = jacobianFrom(centralDifferences(
      s.x, [&](const std::vector<mpreal>& at) { return column(robotForwardDynamics(model, at, xd, tau, kGravity)); }));
  const MatrixMp by_xd = jacobianFrom(centralDifferences(
      s.xd, [&](const std::vector<mpreal>& at) { return column(robotForwardDynamics(model, x, at, tau, kGravity)); }));
  const MatrixMp inverse = robotInverseMass(model, x);
  const Derivatives ours = robotForwardDynamicsDerivatives(model, s, kGravity);
  recordMax(table, "dfd_dx.ours", relativeError(ours.by_x, by_x));
  recordMax(table, "dfd_dxd.ours", relativeError(ours.by_xd, by_xd));
  recordMax(table, "minv.ours", relativeError(ours.inverse_mass, inverse));
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm& pin = peersOf(robot).pinocchioOracle();
  if (!pin.permutation())
    return;
  const auto peer = pin.model.abaDerivatives(pin.configuration(s.x.data()), pin.velocity(s.xd.data()),
                                             pin.velocity(s.tau.data()));
  const Eigen::MatrixXd& A = pin.A;
  recordMax(table, "dfd_dx.pinocchio", relativeError(Eigen::MatrixXd(A.transpose() * peer.ddq_dq * A), by_x));
  recordMax(table, "dfd_dxd.pinocchio", relativeError(Eigen::MatrixXd(A.transpose() * peer.ddq_dv * A), by_xd));
  recordMax(table, "minv.pinocchio", relativeError(Eigen::MatrixXd(A.transpose() * peer.Minv * A), inverse));
#endif
}
}  // namespace

ErrorTable dynamicsErrors(const Robot& robot)
{
  const Precision256 precision;
  const RobotModel model = modelOf(robot);
  ErrorTable table;
  const std::vector<RobotState> states = errorStates(robot);
  for (const RobotState& s : states)
  {
    const MatrixMp tau = column(robotInverseDynamics(model, toScalar<mpreal>(s.x), toScalar<mpreal>(s.xd),
                                                     toScalar<mpreal>(s.xdd), kGravity));
    recordMax(table, "tau.ours",
              relativeError(Eigen::MatrixXd(robotInverseDynamics(model, s.x, s.xd, s.xdd, kGravity)), tau));
    peerTauErrors(robot, s, tau, table);
    const MatrixMp xdd = column(robotForwardDynamics(model, toScalar<mpreal>(s.x), toScalar<mpreal>(s.xd),
                                                     toScalar<mpreal>(s.tau), kGravity));
    recordMax(table, "fd.ours", relativeError(Eigen::MatrixXd(robotForwardDynamics(model, s.x, s.xd, s.tau, kGravity)), xdd));
    peerForwardDynamicsErrors(robot, s, xdd, table);
  }
  for (std::size_t i = 0; i < states.size(); i += 8)
    inverseDynamicsDerivativeErrors(robot, states[i], table);
  for (std::size_t i = 0; i < states.size(); i += 16)
    forwardDynamicsDerivativeErrors(robot, states[i], table);
  return table;
}

}  // namespace drb_bench
