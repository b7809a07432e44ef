// Backprop over a body's vertices stored coordinate by coordinate.
//
// The backprop of vertex_jacobian.h needs two sums per body,
//   W = sum_i g_i p0_i^T (3x3)   and   force = sum_i g_i,
// then dL/dq = backpropFromSums(pose, W, force). The gradients g_i come from
// the client as (x, y, z) per vertex; the vertices p0_i are ours, so they can
// be stored in the layout the sum wants: a structure of arrays (all x, then
// all y, then all z), made once per body. One vector load then holds the x
// (y, z) of 8 vertices (AVX-512) or 4 (AVX2) with no transposition; only the
// gradients are transposed into lanes.
//
// Paths, chosen at run time from CPUID (the package builds for the x86-64
// baseline, no -march): AVX-512F, else AVX2 + FMA, else a portable loop.
// The paths add in different orders, so their results may differ in the
// last bits; each is deterministic.
//
// Large meshes can be split over threads: the vertices are cut into
// contiguous chunks whose sums are added in chunk order, so for a given
// vertex count, thread count and CPU path the result is always the same.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <system_error>
#include <thread>
#include <vector>

#include "diff_rigid_body/vertex_jacobian.h"

namespace diff_rigid_body
{
/// Body-frame vertices, column 0 every x, column 1 every y, column 2 every
/// z [m] (Eigen's column-major N x 3). Make it once per body:
/// `VertexColumns<double> columns = vertices.transpose();` (24 B per vertex).
template <typename Scalar>
using VertexColumns = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;

/// Sums of the backprop over some vertices: W = sum_i g_i p0_i^T, force = sum_i g_i.
template <typename Scalar>
struct VertexGradientSums
{
  Matrix3<Scalar> W = Matrix3<Scalar>::Zero();
  Vector3<Scalar> force = Vector3<Scalar>::Zero();
};

/// Below this many vertices per thread a thread costs more than it saves
/// (starting one is ~10-50 us; 2^16 vertices take ~100 us on one core).
constexpr std::size_t kMinVerticesPerBackpropThread = std::size_t(1) << 16;

namespace detail
{
/// 12 running sums, W row-major (W[3a + b] = sum g_a p0_b) then force.
using GradientSums12 = std::array<double, 12>;

/// Adds vertices [begin, end) one at a time: the tails and the portable path.
inline void addVertexGradientsScalar(const double* x, const double* y, const double* z, const double* g,
                                     std::size_t begin, std::size_t end, GradientSums12& sums)
{
  for (std::size_t n = begin; n < end; ++n)
  {
    const double p[3] = { x[n], y[n], z[n] };
    for (int a = 0; a < 3; ++a)
    {
      const double ga = g[3 * n + a];
      for (int b = 0; b < 3; ++b)
        sums[3 * a + b] += ga * p[b];
      sums[9 + a] += ga;
    }
  }
}

#if defined(DRB_VERTEX_KERNELS_AVX2)
/// Software prefetch distance [vertices]: meshes that do not fit in cache
/// are read at the speed of memory only if the next lines are requested
/// while the current ones are summed (~20 % faster at 10^6 vertices than
/// the hardware prefetcher alone, bench/).
constexpr std::size_t kPrefetchVertices = 128;

/// Requests the lines holding vertices n + kPrefetchVertices .. + 7 (three
/// lines of gradients, one line of each coordinate) unless that is within kPrefetchVertices + 8 of
/// the end. always_inline matters: GCC deletes calls to a function that only
/// prefetches (it counts as free of side effects) unless it is inlined first.
__attribute__((always_inline)) inline void prefetchVertex(const double* x, const double* y, const double* z,
                                                          const double* g, std::size_t n, std::size_t count)
{
  if (n + kPrefetchVertices + 8 > count)
    return;
  const std::size_t a = n + kPrefetchVertices;
  _mm_prefetch(reinterpret_cast<const char*>(g + 3 * a), _MM_HINT_T0);
  _mm_prefetch(reinterpret_cast<const char*>(g + 3 * a + 8), _MM_HINT_T0);
  _mm_prefetch(reinterpret_cast<const char*>(g + 3 * a + 16), _MM_HINT_T0);
  _mm_prefetch(reinterpret_cast<const char*>(x + a), _MM_HINT_T0);
  _mm_prefetch(reinterpret_cast<const char*>(y + a), _MM_HINT_T0);
  _mm_prefetch(reinterpret_cast<const char*>(z + a), _MM_HINT_T0);
}

inline bool cpuHasAvx512f()
{
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f");
  }();
  return has;
}

/// Vertices [0, 8 floor(count / 8)), 8 per register. The gradients of 8
/// vertices are 24 values r0 = g[0..8), r1 = g[8..16), r2 = g[16..24);
/// two two-source permutes per coordinate gather (g_x of vertices 0..7) etc.
/// Returns the vertices done.
__attribute__((target("avx512f"))) inline std::size_t addVertexGradientsAvx512(const double* x, const double* y,
                                                                              const double* z, const double* g,
                                                                              std::size_t count, GradientSums12& sums)
{
  // Stage 1 picks from (r0, r1) (indices 0..15), stage 2 adds r2 (8..15 = r2[0..8)).
  const __m512i x01 = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), x2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13);
  const __m512i y01 = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), y2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14);
  const __m512i z01 = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), z2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15);
  // Fixed-count loops are unrolled (pragma) so that acc lives in registers.
  __m512d acc[12];  // W row-major, then force
#pragma GCC unroll 12
  for (__m512d& a : acc)
    a = _mm512_setzero_pd();
  std::size_t n = 0;
  for (; n + 8 <= count; n += 8)
  {
    prefetchVertex(x, y, z, g, n, count);
    const double* v = g + 3 * n;
    const __m512d r0 = _mm512_loadu_pd(v), r1 = _mm512_loadu_pd(v + 8), r2 = _mm512_loadu_pd(v + 16);
    const __m512d G[3] = { _mm512_permutex2var_pd(_mm512_permutex2var_pd(r0, x01, r1), x2, r2),
                           _mm512_permutex2var_pd(_mm512_permutex2var_pd(r0, y01, r1), y2, r2),
                           _mm512_permutex2var_pd(_mm512_permutex2var_pd(r0, z01, r1), z2, r2) };
    const __m512d P[3] = { _mm512_loadu_pd(x + n), _mm512_loadu_pd(y + n), _mm512_loadu_pd(z + n) };
#pragma GCC unroll 3
    for (int a = 0; a < 3; ++a)
    {
#pragma GCC unroll 3
      for (int b = 0; b < 3; ++b)
        acc[3 * a + b] = _mm512_fmadd_pd(G[a], P[b], acc[3 * a + b]);
      acc[9 + a] = _mm512_add_pd(acc[9 + a], G[a]);
    }
  }
  // Lanes (0..7) added as ((0 + 4) + (2 + 6)) + ((1 + 5) + (3 + 7)). (The
  // zero-masked extracts say the same as the plain ones, without GCC 12's
  // false -Wuninitialized on those.)
#pragma GCC unroll 12
  for (int k = 0; k < 12; ++k)
  {
    const __m256d half =
        _mm256_add_pd(_mm512_maskz_extractf64x4_pd(0xFF, acc[k], 0), _mm512_maskz_extractf64x4_pd(0xFF, acc[k], 1));
    const __m128d quarter = _mm_add_pd(_mm256_castpd256_pd128(half), _mm256_extractf128_pd(half, 1));
    sums[k] += _mm_cvtsd_f64(_mm_add_sd(quarter, _mm_unpackhi_pd(quarter, quarter)));
  }
  return n;
}

/// Vertices [0, 4 floor(count / 4)), 4 per register (transpose4Vertices of
/// vertex_jacobian.h for the gradients). Returns the vertices done.
__attribute__((target("avx2,fma"))) inline std::size_t addVertexGradientsAvx2(const double* x, const double* y,
                                                                             const double* z, const double* g,
                                                                             std::size_t count, GradientSums12& sums)
{
  // Fixed-count loops are unrolled (pragma) so that acc lives in registers.
  __m256d acc[12];  // W row-major, then force
#pragma GCC unroll 12
  for (__m256d& a : acc)
    a = _mm256_setzero_pd();
  std::size_t n = 0;
  for (; n + 4 <= count; n += 4)
  {
    if (n % 8 == 0)  // once per line of each array
      prefetchVertex(x, y, z, g, n, count);
    __m256d G[3];
    transpose4Vertices(g + 3 * n, G);
    const __m256d P[3] = { _mm256_loadu_pd(x + n), _mm256_loadu_pd(y + n), _mm256_loadu_pd(z + n) };
#pragma GCC unroll 3
    for (int a = 0; a < 3; ++a)
    {
#pragma GCC unroll 3
      for (int b = 0; b < 3; ++b)
        acc[3 * a + b] = _mm256_fmadd_pd(G[a], P[b], acc[3 * a + b]);
      acc[9 + a] = _mm256_add_pd(acc[9 + a], G[a]);
    }
  }
  // Lanes (0..3) added as (0 + 2) + (1 + 3).
#pragma GCC unroll 12
  for (int k = 0; k < 12; ++k)
  {
    const __m128d half = _mm_add_pd(_mm256_castpd256_pd128(acc[k]), _mm256_extractf128_pd(acc[k], 1));
    sums[k] += _mm_cvtsd_f64(_mm_add_sd(half, _mm_unpackhi_pd(half, half)));
  }
  return n;
}
#endif

/// The 12 sums over vertices [begin, end); g points at vertex begin's gradient.
inline GradientSums12 sumVertexGradientsRange(const VertexColumns<double>& columns, const double* g,
                                              std::size_t begin, std::size_t end)
{
  GradientSums12 sums{};
  const double* x = columns.col(0).data() + begin;
  const double* y = columns.col(1).data() + begin;
  const double* z = columns.col(2).data() + begin;
  const std::size_t count = end - begin;
  std::size_t done = 0;
#if defined(DRB_VERTEX_KERNELS_AVX2)
  if (cpuHasAvx512f())
    done = addVertexGradientsAvx512(x, y, z, g, count, sums);
  else if (cpuHasAvx2Fma())
    done = addVertexGradientsAvx2(x, y, z, g, count, sums);
#endif
  addVertexGradientsScalar(x, y, z, g, done, count, sums);
  return sums;
}
/// Adds per-chunk sums in chunk order (deterministic) into W and force.
inline VertexGradientSums<double> toVertexGradientSums(const GradientSums12* partial, std::size_t chunks)
{
  VertexGradientSums<double> sums;
  for (std::size_t c = 0; c < chunks; ++c)
  {
    const GradientSums12& p = partial[c];
    for (int k = 0; k < 9; ++k)
      sums.W(k / 3, k % 3) += p[k];
    for (int k = 0; k < 3; ++k)
      sums.force[k] += p[9 + k];
  }
  return sums;
}
}  // namespace detail

/// W = sum_i g_i p0_i^T and force = sum_i g_i over all vertices, on up to
/// `threads` threads (the calling one included); fewer when the mesh has
/// under kMinVerticesPerBackpropThread vertices per thread.
///
/// \param gradients dL/dp, 3 per vertex in vertex order [any unit / m]
inline VertexGradientSums<double> sumVertexGradients(const VertexColumns<double>& columns, const double* gradients,
                                                     unsigned threads = 1)
{
  const std::size_t count = static_cast<std::size_t>(columns.rows());
  const std::size_t chunks =
      std::max<std::size_t>(1, std::min<std::size_t>(threads, count / kMinVerticesPerBackpropThread));
  if (chunks == 1)  // no allocation, no thread
  {
    const detail::GradientSums12 all = detail::sumVertexGradientsRange(columns, gradients, 0, count);
    return detail::toVertexGradientSums(&all, 1);
  }
  std::vector<detail::GradientSums12> partial(chunks);
  auto chunkBegin = [&](std::size_t c) { return count * c / chunks; };
  auto run = [&](std::size_t c) {
    partial[c] = detail::sumVertexGradientsRange(columns, gradients + 3 * chunkBegin(c), chunkBegin(c),
                                                 chunkBegin(c + 1));
  };
  std::vector<std::thread> helpers;
  helpers.reserve(chunks - 1);
  for (std::size_t c = 1; c < chunks; ++c)
  {
    try
    {
      helpers.emplace_back(run, c);
    }
    catch (...)  // no thread available (system_error, bad_alloc): do the chunk here
    {
      run(c);
    }
  }
  run(0);
  for (std::thread& t : helpers)
    t.join();
  return detail::toVertexGradientSums(partial.data(), chunks);
}

/// dL/dq = sum_i J_i^T g_i over all vertices of a body stored by coordinate
/// (same result as backpropagateVertexGradients of vertex_jacobian.h up to
/// the order of the additions).
inline Vector6<double> backpropagateVertexGradients(const BodyPose<double>& pose, const VertexColumns<double>& columns,
                                                    const double* gradients, unsigned threads = 1)
{
  const VertexGradientSums<double> sums = sumVertexGradients(columns, gradients, threads);
  return backpropFromSums(pose, sums.W, sums.force);
}

}  // namespace diff_rigid_body
