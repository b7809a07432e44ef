// Sines and cosines of many angles at once, for the batched kernels
// (massMatrixBatch, the single-state massMatrix in double). Portable double
// arithmetic written so that the compiler vectorises it; included by rpy.h.
#pragma once

#include <cmath>
#include <cstddef>

namespace diff_rigid_body
{
/// Method and accuracy of sinCos.
///
/// The loop body is branch-free double arithmetic over a block of
/// kSinCosLanes values, so the compiler vectorises it at the baseline ISA
/// (SSE2: 2 lanes; 4 or 8 under -mavx2 / -mavx512f) with no library call:
///   n = nearest integer to x 2/pi   (the 1.5 2^52 rounding trick),
///   r = x - n pi/2                  (Cody-Waite, pi/2 in three 33-bit parts:
///                                    n p1 and n p2 are exact for |n| < 2^20
///                                    and x - n p1 is exact by Sterbenz),
///   sin r, cos r on [-pi/4, pi/4]   (the fdlibm/glibc minimax polynomials),
///   quadrant n mod 4                (selects and signs, no integers).
/// The absolute error of r is below 1.2e-16, so sin x and cos x are within
/// about 2 ulp of 1 (absolute) of the exact values. A block holding any
/// |x| >= kSinCosFastLimit (1.6e6 rad) or a non-finite value is done with
/// std::sin / std::cos instead, so every input gets a correct answer.
constexpr int kSinCosLanes = 8;
constexpr double kSinCosFastLimit = 1.6e6;  // < 2^20 pi/2

namespace detail
{
/// N angles, all with |x| < kSinCosFastLimit.
template <int N>
inline void sinCosLanes(const double* x, double* s, double* c)
{
  constexpr double two_over_pi = 6.36619772367581382433e-01;
  constexpr double p1 = 1.57079632673412561417e+00;  // first 33 bits of pi/2
  constexpr double p2 = 6.07710050630396597660e-11;  // next 33 bits
  constexpr double p3 = 2.02226624871116645580e-21;  // next 33 bits
  constexpr double round_magic = 6755399441055744.0;  // 1.5 2^52: (y + m) - m rounds y to an integer
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  for (int i = 0; i < N; ++i)
  {
    const double xi = x[i];
    const double n = (xi * two_over_pi + round_magic) - round_magic;
    double r = xi - n * p1;
    r = r - n * p2;
    r = r - n * p3;
    const double z = r * r;
    const double sr = r + (r * z) * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    const double hz = 0.5 * z;
    const double w = 1.0 - hz;
    const double cr = w + (((1.0 - w) - hz) + (z * z) * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6))))));
    // q = n mod 4 in {0, 1, 2, 3}, exactly: floor(n / 4) = round(n / 4 - 3/8) has no ties.
    const double q = n - 4.0 * (((n * 0.25 - 0.375) + round_magic) - round_magic);
    const bool odd = (q == 1.0) | (q == 3.0);
    const double sin_abs = odd ? cr : sr;
    const double cos_abs = odd ? sr : cr;
    s[i] = q >= 2.0 ? -sin_abs : sin_abs;
    c[i] = ((q == 1.0) | (q == 2.0)) ? -cos_abs : cos_abs;
  }
}

/// true when all N values may take the fast path.
template <int N = kSinCosLanes>
inline bool sinCosBlockIsFast(const double* x)
{
  bool fast = true;
  for (int i = 0; i < N; ++i)
    fast &= std::abs(x[i]) < kSinCosFastLimit;  // false for NaN as well
  return fast;
}

/// N angles of any value: the fast lanes when all allow it, else std::sin / std::cos.
template <int N>
inline void sinCosChecked(const double* x, double* s, double* c)
{
  if (sinCosBlockIsFast<N>(x))
  {
    sinCosLanes<N>(x, s, c);
    return;
  }
  for (int k = 0; k < N; ++k)
  {
    s[k] = std::sin(x[k]);
    c[k] = std::cos(x[k]);
  }
}

/// sin and cos of two angles (one SSE2 register): the single-state kernels.
inline void sinCos2(const double* x, double* s, double* c)
{
  sinCosChecked<2>(x, s, c);
}
}  // namespace detail

/// s[i] = sin(x[i]), c[i] = cos(x[i]) for i < count (see kSinCosLanes above
/// for the method and its accuracy). The arrays may not overlap.
inline void sinCos(const double* x, std::size_t count, double* s, double* c)
{
  std::size_t i = 0;
  for (; i + kSinCosLanes <= count; i += kSinCosLanes)
    detail::sinCosChecked<kSinCosLanes>(x + i, s + i, c + i);
  if (i < count)  // the last count - i < kSinCosLanes values, padded with 0
  {
    const std::size_t rest = count - i;
    double xs[kSinCosLanes] = {}, ss[kSinCosLanes], cs[kSinCosLanes];
    for (std::size_t k = 0; k < rest; ++k)
      xs[k] = x[i + k];
    detail::sinCosChecked<kSinCosLanes>(xs, ss, cs);
    for (std::size_t k = 0; k < rest; ++k)
    {
      s[i + k] = ss[k];
      c[i + k] = cs[k];
    }
  }
}

}  // namespace diff_rigid_body
