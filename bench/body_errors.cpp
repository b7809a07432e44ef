// M(x) and dM/dx against MPFR (body_errors.h), keys
//   M.ours, M.ours_chain_mass, M.kdl, M.mujoco, M.pinocchio, dM.ours
// (M.ours_chain_mass and M.kdl against the reference of the mass KDL's
// chain covers).
#include "body_errors.h"

#include <Eigen/Eigenvalues>

#include "mpfr_reference.h"
#include "robot_peers.h"

namespace drb_bench
{
namespace
{
void peerMassMatrixErrors(const Robot& robot, const RobotState& s, const MatrixMp& ref, ErrorTable& table)
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
    const MatrixMp ref_chain = robotMassMatrix(chain, toScalar<mpreal>(s.x));
    recordMax(table, "M.ours_chain_mass", relativeError(robotMassMatrix(chain, s.x), ref_chain));
    kdl.massMatrix(s.x.data());
    recordMax(table, "M.kdl", relativeError(kdl.massMatrixInCoordinates(d), ref_chain));
  }
#endif
#ifdef DRB_BENCH_HAVE_MUJOCO
  if (!peers.mujoco->has_free_joint)
  {
    peers.mujoco->massMatrix(s.x.data());
    recordMax(table, "M.mujoco", relativeError(peers.mujoco->massMatrixInCoordinates(d), ref));
  }
#endif
#ifdef DRB_BENCH_HAVE_PINOCCHIO
  PinocchioArm& pin = peers.pinocchioOracle();
  const Eigen::MatrixXd M = pin.A.transpose() * pin.model.crba(pin.configuration(s.x.data())) * pin.A;
  recordMax(table, "M.pinocchio", relativeError(M, ref));
#endif
}
}  // namespace

double massMatrixConditioning(const Robot& robot)
{
  double worst = 0;
  for (const RobotState& s : errorStates(robot))
  {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(robotMassMatrix(modelOf(robot), s.x),
                                                               Eigen::EigenvaluesOnly);
    worst = std::max(worst, eigen.eigenvalues().maxCoeff() / eigen.eigenvalues().minCoeff());
  }
  return worst;
}

ErrorTable bodyErrors(const Robot& robot)
{
  const Precision256 precision;
  const RobotModel model = modelOf(robot);
  ErrorTable table;
  const std::vector<RobotState> states = errorStates(robot);
  for (const RobotState& s : states)
  {
    const MatrixMp ref = robotMassMatrix(model, toScalar<mpreal>(s.x));
    recordMax(table, "M.ours", relativeError(robotMassMatrix(model, s.x), ref));
    peerMassMatrixErrors(robot, s, ref, table);
  }
  for (std::size_t i = 0; i < states.size(); i += 8)
  {
    const std::vector<MatrixMp> ref = centralDifferences(
        states[i].x, [&](const std::vector<mpreal>& x) { return robotMassMatrix(model, x); });
    recordMax(table, "dM.ours", relativeError(robotMassMatrixDerivatives(model, states[i].x), ref));
  }
  return table;
}

}  // namespace drb_bench
