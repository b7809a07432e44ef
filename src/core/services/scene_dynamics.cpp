// SceneQueries::inverseDynamics and forwardDynamics: the requests' checks
// and layout (as get_mass_matrix's), and the algorithms per body and
// configuration (rnea.h, rnea_derivatives.h, forward_dynamics.h).
#include <cmath>
#include <initializer_list>
#include <sstream>

#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "services/request_checks.h"
#include "services/request_layout.h"

namespace diff_rigid_body
{
using detail::checkDynamicsBudget;
using detail::forEachBodySlot;
using detail::reject;
using detail::requireFiniteResults;
using detail::setBodies;
using detail::sizeMismatch;
using detail::slice;

namespace
{
/// `matrix` (d x d, column-major) row-major at `out`, times `scale`.
void writeRowMajor(const Eigen::MatrixXd& matrix, double scale, double* out)
{
  const Eigen::Index d = matrix.rows();
  for (Eigen::Index r = 0; r < d; ++r)
    for (Eigen::Index c = 0; c < d; ++c)
      out[r * d + c] = scale * matrix(r, c);
}

/// Why forward dynamics is undefined at x: the coordinate forwardDynamics
/// reported (THETA at a free root's gimbal lock, else a singular pivot of H).
std::string singularReason(const BodyModel& body, const double* x, int coordinate)
{
  std::ostringstream why;
  why.precision(17);
  if (body.hasFreeRoot() && !(std::abs(std::cos(x[THETA])) >= kGimbalLockCosine))
    why << "its Euler angles are at gimbal lock: pitch theta = " << x[THETA] << " rad, cos(theta) = "
        << std::cos(x[THETA])
        << ", below 4 DBL_EPSILON = 8.9e-16 (the chart (phi, theta, psi) is singular there: the rates of phi and psi "
           "are not defined)";
  else if (body.hasFreeRoot() && coordinate < 3)
    why << "its free root's rotation moves no inertia about the fixed axis " << "xyz"[coordinate]
        << " (a principal moment of inertia 0)";
  else if (body.hasFreeRoot() && coordinate < 6)
    why << "its free root moves no mass (coordinate x[" << coordinate << "])";
  else
    why << "coordinate x[" << coordinate << "] (joint '"
        << body.joint_names[static_cast<std::size_t>(coordinate) - body.rootCoordinates()] << "') moves no mass";
  return why.str();
}

}  // namespace

void SceneQueries::inverseDynamics(const SceneState& current, const std::vector<std::string>& bodies,
                                   DoubleView q, DoubleView qdot,
                                   DoubleView qddot, bool coriolis_matrices, bool derivatives,
                                   InverseDynamicsAnswer& answer) const
{
  const detail::BatchedBodies batch =
      detail::batchedBodies(*this, bodies, q, { { "qdot", &qdot }, { "qddot", &qddot } });
  const std::vector<std::size_t>& indices = batch.indices;
  const detail::RequestLayout& layout = batch.layout;
  const std::size_t K = batch.K, n = indices.size();
  const std::size_t matrices = (coriolis_matrices ? 1 : 0) + (derivatives ? 2 : 0);
  checkDynamicsBudget(K, 3 * layout.D + matrices * layout.per_m + n, matrices > 0);
  setBodies(*this, indices, answer);
  answer.tau.resize(K * layout.D);
  answer.velocity_terms.resize(K * layout.D);
  answer.gravity_terms.resize(K * layout.D);
  answer.coriolis_matrices.resize(coriolis_matrices ? K * layout.per_m : 0);
  answer.dtau_dq.resize(derivatives ? K * layout.per_m : 0);
  answer.dtau_dqdot.resize(derivatives ? K * layout.per_m : 0);
  forEachBodySlot(*this, layout, indices, K, current, q, answer.cos_theta, [&](const detail::BodySlot& slot) {
    BodyWorkspace<double>& ws = workspace(slot.body);
    const std::size_t v = slot.v, m = slot.m;
    inverseDynamicsTerms(scene_.bodies[slot.body], ws, slot.x, slice(qdot, v), slice(qddot, v), gravity_,
                         answer.tau.data() + v, answer.velocity_terms.data() + v, answer.gravity_terms.data() + v,
                         matrices > 0 ? &ws.derivative_x : nullptr, &ws.derivative_xd);
    if (coriolis_matrices)
      writeRowMajor(ws.derivative_xd, 0.5, answer.coriolis_matrices.data() + m);
    if (derivatives)
    {
      writeRowMajor(ws.derivative_x, 1.0, answer.dtau_dq.data() + m);
      writeRowMajor(ws.derivative_xd, 1.0, answer.dtau_dqdot.data() + m);
    }
  });
  requireFiniteResults({ { "result tau", &answer.tau },
                         { "result velocity_terms", &answer.velocity_terms },
                         { "result gravity_terms", &answer.gravity_terms },
                         { "result coriolis_matrices", &answer.coriolis_matrices },
                         { "result dtau_dq", &answer.dtau_dq },
                         { "result dtau_dqdot", &answer.dtau_dqdot } });
}

void SceneQueries::forwardDynamics(const SceneState& current, const std::vector<std::string>& bodies,
                                   DoubleView q, DoubleView qdot,
                                   DoubleView tau, bool derivatives,
                                   ForwardDynamicsAnswer& answer) const
{
  const detail::BatchedBodies batch = detail::batchedBodies(*this, bodies, q, { { "qdot", &qdot }, { "tau", &tau } });
  const std::vector<std::size_t>& indices = batch.indices;
  const detail::RequestLayout& layout = batch.layout;
  const std::size_t K = batch.K, n = indices.size();
  checkDynamicsBudget(K, layout.D + (derivatives ? 3 * layout.per_m : 0) + n, derivatives);
  setBodies(*this, indices, answer);
  answer.qddot.resize(K * layout.D);
  answer.dqddot_dq.resize(derivatives ? K * layout.per_m : 0);
  answer.dqddot_dqdot.resize(derivatives ? K * layout.per_m : 0);
  answer.dqddot_dtau.resize(derivatives ? K * layout.per_m : 0);
  forEachBodySlot(*this, layout, indices, K, current, q, answer.cos_theta, [&](const detail::BodySlot& slot) {
    const BodyModel& body = scene_.bodies[slot.body];
    BodyWorkspace<double>& ws = workspace(slot.body);
    const double *xd = slice(qdot, slot.v), *generalized_force = slice(tau, slot.v);
    double* xdd = answer.qddot.data() + slot.v;
    const int singular = derivatives ? forwardDynamicsDerivatives(body, ws, slot.x, xd, generalized_force, gravity_,
                                                                  xdd, ws.derivative_x, ws.derivative_xd,
                                                                  ws.inverse_mass) :
                                       diff_rigid_body::forwardDynamics(body, ws, slot.x, xd, generalized_force,
                                                                        gravity_, xdd);
    if (singular >= 0)
      reject((K > 1 ? "q (configuration " + std::to_string(slot.n / n) + ")" : std::string("q")) + ": body '" +
             body.name + "': M(x) is singular, so forward dynamics is undefined there: " +
             singularReason(body, slot.x, singular));
    if (derivatives)
    {
      writeRowMajor(ws.derivative_x, 1.0, answer.dqddot_dq.data() + slot.m);
      writeRowMajor(ws.derivative_xd, 1.0, answer.dqddot_dqdot.data() + slot.m);
      writeRowMajor(ws.inverse_mass, 1.0, answer.dqddot_dtau.data() + slot.m);
    }
  });
  requireFiniteResults({ { "result qddot", &answer.qddot },
                         { "result dqddot_dq", &answer.dqddot_dq },
                         { "result dqddot_dqdot", &answer.dqddot_dqdot },
                         { "result dqddot_dtau", &answer.dqddot_dtau } });
}

}  // namespace diff_rigid_body
