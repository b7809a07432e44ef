// The MPFR side of body_errors.h: relative errors taken in 256 bits, and
// central differences of an mpreal function of x with h = 2^-100.
#pragma once

#include <algorithm>
#include <functional>
#include <vector>

#include <mpreal.h>
#include <unsupported/Eigen/MPRealSupport>

#include "robot_kernels.h"

namespace drb_bench
{
using mpfr::mpreal;
using MatrixMp = MatrixX<mpreal>;

/// Sets the default mpreal precision to 256 bits for its lifetime.
struct Precision256
{
  mp_prec_t previous = mpreal::get_default_prec();
  Precision256() { mpreal::set_default_prec(256); }
  ~Precision256() { mpreal::set_default_prec(previous); }
};

/// max|A - ref| / max|ref| over every entry, in 256 bits.
inline double relativeError(const Eigen::MatrixXd& A, const MatrixMp& ref)
{
  mpreal diff = 0, scale = 0;
  for (Eigen::Index i = 0; i < ref.rows(); ++i)
    for (Eigen::Index j = 0; j < ref.cols(); ++j)
    {
      diff = std::max(diff, mpfr::abs(mpreal(A(i, j)) - ref(i, j)));
      scale = std::max(scale, mpfr::abs(ref(i, j)));
    }
  return (diff / scale).toDouble();
}

/// The same over a list of matrices (dM/dx_j, j < d): max over all of them.
inline double relativeError(const std::vector<Eigen::MatrixXd>& A, const std::vector<MatrixMp>& ref)
{
  mpreal diff = 0, scale = 0;
  for (std::size_t k = 0; k < ref.size(); ++k)
    for (Eigen::Index i = 0; i < ref[k].rows(); ++i)
      for (Eigen::Index j = 0; j < ref[k].cols(); ++j)
      {
        diff = std::max(diff, mpfr::abs(mpreal(A[k](i, j)) - ref[k](i, j)));
        scale = std::max(scale, mpfr::abs(ref[k](i, j)));
      }
  return (diff / scale).toDouble();
}

/// Central differences of f (a d-vector or d x d matrix of mpreal) along
/// each of the d entries of `at`: element j is (f(at + h e_j) - f(at - h e_j)) / 2h.
inline std::vector<MatrixMp> centralDifferences(const std::vector<double>& at,
                                                const std::function<MatrixMp(const std::vector<mpreal>&)>& f)
{
  const mpreal h = mpfr::pow(mpreal(2), -100);
  std::vector<MatrixMp> out;
  for (std::size_t j = 0; j < at.size(); ++j)
  {
    std::vector<mpreal> plus = toScalar<mpreal>(at), minus = plus;
    plus[j] += h;
    minus[j] -= h;
    out.push_back((f(plus) - f(minus)) / (2 * h));
  }
  return out;
}

/// The columns j of a Jacobian from central differences of a vector (each d x 1).
inline MatrixMp jacobianFrom(const std::vector<MatrixMp>& columns)
{
  MatrixMp J(columns.empty() ? 0 : columns[0].rows(), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t j = 0; j < columns.size(); ++j)
    J.col(static_cast<Eigen::Index>(j)) = columns[j].col(0);
  return J;
}

}  // namespace drb_bench
