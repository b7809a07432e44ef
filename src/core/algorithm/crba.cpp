#include "diff_rigid_body/algorithm/crba.h"

#include <algorithm>
#include <cmath>

#include "diff_rigid_body/algorithm/free_body/mass_matrix.h"

namespace diff_rigid_body
{
template void crba<double>(const BodyModel&, BodyWorkspace<double>&, const double*);
template void crbaFromKinematics<double>(const BodyModel&, BodyWorkspace<double>&);

namespace
{
// A free object's M(q_k) and cos(theta_k) by massMatrixBatch (vectorised
// sinCos over blocks of states, M written entry by entry). Adjacent slots
// (m_stride 36, cos_stride 1) are written in place; otherwise (several
// bodies per configuration) blocks of states go through an L1 buffer.
void freeObjectMassMatrices(const Segment& body, const double* x, std::size_t count, std::size_t stride,
                            std::size_t m_stride, std::size_t cos_stride, double* mass_matrices, double* cos_theta)
{
  const double mass = body.inertia.mass;
  const Eigen::Matrix3d& inertia = body.inertia.inertia;
  if ((m_stride == 36 && cos_stride == 1) || count == 1)
  {
    massMatrixBatch(x, count, stride, mass, inertia, mass_matrices, cos_theta);
    return;
  }
  constexpr std::size_t kBlock = 64;  // 18 KiB of matrices
  double block[36 * kBlock], cos_block[kBlock];
  for (std::size_t k0 = 0; k0 < count; k0 += kBlock)
  {
    const std::size_t m = std::min(kBlock, count - k0);
    massMatrixBatch(x + k0 * stride, m, stride, mass, inertia, block, cos_block);
    for (std::size_t j = 0; j < m; ++j)
    {
      std::copy(block + 36 * j, block + 36 * (j + 1), mass_matrices + (k0 + j) * m_stride);
      cos_theta[(k0 + j) * cos_stride] = cos_block[j];
    }
  }
}
}  // namespace

void massMatrices(const BodyModel& model, BodyWorkspace<double>& ws, const double* x, std::size_t count,
                  std::size_t stride, std::size_t m_stride, std::size_t cos_stride, double* mass_matrices,
                  double* cos_theta)
{
  if (model.closedFormKernels())
  {
    freeObjectMassMatrices(model.segments[0], x, count, stride, m_stride, cos_stride, mass_matrices, cos_theta);
    return;
  }
  const Eigen::Index d = static_cast<Eigen::Index>(model.coordinates);
  for (std::size_t k = 0; k < count; ++k)
  {
    const double* xk = x + k * stride;
    crba(model, ws, xk);
    // M is symmetric: its column-major storage is its row-major one.
    std::copy(ws.M.data(), ws.M.data() + d * d, mass_matrices + k * m_stride);
    cos_theta[k * cos_stride] = model.hasFreeRoot() ? std::cos(xk[THETA]) : 1.0;
  }
}

}  // namespace diff_rigid_body
