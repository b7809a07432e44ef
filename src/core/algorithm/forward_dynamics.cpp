#include "diff_rigid_body/algorithm/forward_dynamics.h"

namespace diff_rigid_body
{
template int forwardDynamics<double>(const BodyModel&, BodyWorkspace<double>&, const double*, const double*,
                                     const double*, const Vector3<double>&, double*);
template int forwardDynamicsDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                                const double*, const double*, const Vector3<double>&, double*,
                                                Eigen::MatrixXd&, Eigen::MatrixXd&, Eigen::MatrixXd&);
}  // namespace diff_rigid_body
