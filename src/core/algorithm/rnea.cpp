#include "diff_rigid_body/algorithm/rnea.h"
#include "diff_rigid_body/algorithm/rnea_derivatives.h"

namespace diff_rigid_body
{
template void inverseDynamics<double>(const BodyModel&, BodyWorkspace<double>&, const double*, const double*,
                                      const double*, const Vector3<double>&, double*);
template void inverseDynamicsTerms<double>(const BodyModel&, BodyWorkspace<double>&, const double*, const double*,
                                           const double*, const Vector3<double>&, double*, double*, double*,
                                           Eigen::MatrixXd*, Eigen::MatrixXd*);
template void inverseDynamicsDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*,
                                                 const double*, const double*, const Vector3<double>&,
                                                 Eigen::MatrixXd&, Eigen::MatrixXd&);
}  // namespace diff_rigid_body
