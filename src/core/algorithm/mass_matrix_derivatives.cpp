#include "diff_rigid_body/algorithm/mass_matrix_derivatives.h"

#include "diff_rigid_body/algorithm/free_body/mass_matrix.h"

namespace diff_rigid_body
{
template void massMatrixDerivatives<double>(const BodyModel&, BodyWorkspace<double>&, const double*, double*);

void massMatrixDerivativesRowMajor(const BodyModel& model, BodyWorkspace<double>& ws, const double* x, double* dM,
                                   bool crba_done)
{
  if (!model.closedFormKernels())
  {
    if (!crba_done)
      crba(model, ws, x);
    massMatrixDerivativesFromCrba(model, ws, dM);
    return;
  }
  const std::array<Matrix6<double>, 6> closed_form =
      diff_rigid_body::massMatrixDerivatives(RpyTrig<double>(x[PHI], x[THETA], 0.0), model.segments[0].inertia.inertia);
  for (int j = 0; j < 6; ++j)
    Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(dM + 36 * j) = closed_form[j];
}

}  // namespace diff_rigid_body
