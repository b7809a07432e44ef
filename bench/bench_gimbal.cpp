// Forward dynamics near gimbal lock, errors against MPFR as a function of k:
// pitch theta = +-(pi/2 - 10^-k), k = 1..12, for the free brick (a full
// inertia tensor) and the floating humanoid (35 coordinates), the other
// angles, rates and forces random (test/support/gimbal_reference.h, the
// states and the 256-bit reference the unit test uses).
//
// Rows per body and k (the worse of the two signs), normwise relative:
//   ours        x'', dx''/dx, dx''/dx', M^-1 of forwardDynamicsDerivatives
//               (motion coordinates inside, the chart at the edge);
//   solve_m     x'' by solving M x'' = tau - c - g in double (Eigen's LDL^T
//               of the same M, c, g): what a solve with M loses, the route
//               before Version 4.
// Writes JSON to argv[1] (or stdout).
#include <cstdio>
#include <map>
#include <string>

#include "diff_rigid_body/algorithm/forward_dynamics.h"
#include "../test/support/dynamics_fixtures.h"
#include "../test/support/gimbal_reference.h"

namespace
{
namespace drb = diff_rigid_body;
using namespace drb_test::gimbal;
const Eigen::Vector3d kGravity(0.4, -0.3, -9.81);  // [m/s^2]

struct Row
{
  double xdd = 0, by_x = 0, by_xd = 0, inverse_mass = 0, solve_m = 0;
};

double solveWithM(const drb::BodyModel& model, const State& s, const VectorMp& reference)
{
  drb::BodyWorkspace<double> ws(model);
  Eigen::VectorXd bias(s.x.size());
  drb::inverseDynamics(model, ws, s.x.data(), s.xd.data(), static_cast<const double*>(nullptr), kGravity,
                       bias.data());
  drb::crba(model, ws, s.x.data());
  const Eigen::VectorXd xdd = ws.M.ldlt().solve(s.tau - bias);
  return relativeError(xdd, MatrixMp(reference), { 0 });
}

Row errorsAt(const drb::BodyModel& model, const State& s)
{
  const Eigen::Index d = s.x.size();
  std::vector<Eigen::Index> all;
  for (Eigen::Index j = 0; j < d; ++j)
    all.push_back(j);
  drb::BodyWorkspace<double> ws(model);
  Eigen::VectorXd xdd(d);
  Eigen::MatrixXd by_x(d, d), by_xd(d, d), inverse_mass(d, d);
  Row row;
  if (drb::forwardDynamicsDerivatives(model, ws, s.x.data(), s.xd.data(), s.tau.data(), kGravity, xdd.data(), by_x,
                                      by_xd, inverse_mass) >= 0)
    return { 1, 1, 1, 1, 1 };
  const VectorMp reference = referenceForwardDynamics(model, s.x.cast<Mp>(), s.xd.cast<Mp>(), s.tau.cast<Mp>(), kGravity);
  row.xdd = relativeError(xdd, MatrixMp(reference), { 0 });
  row.by_x = relativeError(by_x, referenceDerivative(model, s.x, s.xd, s.tau, kGravity, false, all), all);
  row.by_xd = relativeError(by_xd, referenceDerivative(model, s.x, s.xd, s.tau, kGravity, true, all), all);
  drb::BodyWorkspace<Mp> wm(model);
  drb::crba(model, wm, s.x.cast<Mp>().eval().data());
  row.inverse_mass = relativeError(inverse_mass, MatrixMp(wm.M.inverse()), all);
  row.solve_m = solveWithM(model, s, reference);
  return row;
}
}  // namespace

int main(int argc, char** argv)
{
  mpfr::mpreal::set_default_prec(256);
  std::FILE* out = argc > 1 ? std::fopen(argv[1], "w") : stdout;
  if (!out)
    return 1;
  std::fprintf(out, "{\n");
  bool first_body = true;
  for (const char* name : { "free_brick", "floating_humanoid" })
  {
    const drb::BodyModel* model = nullptr;
    for (const auto& body : drb_test::dynamics::dynamicsBodies())
      if (body.name == name)
        model = &body.model();
    std::map<int, Row> worst;
    for (const State& s : gimbalStates(*model, 11))
    {
      const Row r = errorsAt(*model, s);
      Row& w = worst[s.k];
      w = { std::max(w.xdd, r.xdd), std::max(w.by_x, r.by_x), std::max(w.by_xd, r.by_xd),
            std::max(w.inverse_mass, r.inverse_mass), std::max(w.solve_m, r.solve_m) };
    }
    std::fprintf(out, "%s  \"%s\": {\"coordinates\": %zu, \"rows\": [\n", first_body ? "" : ",\n", name,
                 model->coordinates);
    for (auto it = worst.begin(); it != worst.end(); ++it)
      std::fprintf(out,
                   "    {\"k\": %d, \"xdd\": %.3e, \"dxdd_dx\": %.3e, \"dxdd_dxd\": %.3e, \"minv\": %.3e, "
                   "\"solve_m\": %.3e}%s\n",
                   it->first, it->second.xdd, it->second.by_x, it->second.by_xd, it->second.inverse_mass,
                   it->second.solve_m, std::next(it) == worst.end() ? "" : ",");
    std::fprintf(out, "  ]}");
    first_body = false;
  }
  std::fprintf(out, "\n}\n");
  if (out != stdout)
    std::fclose(out);
  return 0;
}
