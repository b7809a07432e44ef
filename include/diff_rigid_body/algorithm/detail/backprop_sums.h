// The engine of every double backprop: the 12 sums
//   W = sum_i g_i p0_i^T (3x3, row-major)   and   force = sum_i g_i
// over a run of vertices, whatever the layout of their coordinates.
//
// Vertices are read through an access policy (below): by coordinate
// (VertexColumns), by vertex (Matrix3X, and the gradients), or gathered
// through an index list. One vector load then holds one coordinate of 8
// vertices (AVX-512F) or 4 (AVX2 + FMA), one FMA per product; what is left
// is added one vertex at a time. Paths are chosen at run time from CPUID
// (cpu_features.h). The paths add in different orders, so their results may
// differ in the last bits; each is deterministic.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

#include "diff_rigid_body/algorithm/detail/cpu_features.h"

namespace diff_rigid_body
{
namespace detail
{
/// 12 running sums, W row-major (W[3a + b] = sum g_a p0_b) then force.
using GradientSums12 = std::array<double, 12>;

/// Software prefetch distance [vertices]: meshes that do not fit in cache
/// are read at the speed of memory only if the next lines are requested
/// while the current ones are summed (~20 % faster at 10^6 vertices than
/// the hardware prefetcher alone, bench/).
constexpr std::size_t kPrefetchVertices = 128;

// ---- access policies: vertex n's coordinates ------------------------------
// Each has vertex(n, p) (p[0..2]), an offset copy from(n), prefetch(n) (the
// lines holding vertex n and the next 7), and, under AVX2, load4/load8 (one
// coordinate of 4 or 8 vertices per register).

/// Coordinates stored by vertex: x0 y0 z0 x1 y1 z1 ...
struct ByVertex
{
  const double* p;
  void vertex(std::size_t n, double* out) const
  {
    for (int a = 0; a < 3; ++a)
      out[a] = p[3 * n + a];
  }
  ByVertex from(std::size_t n) const { return { p + 3 * n }; }
#if defined(DRB_VERTEX_KERNELS_AVX2)
  __attribute__((always_inline)) inline void prefetch(std::size_t n) const
  {
    for (int line = 0; line < 3; ++line)
      _mm_prefetch(reinterpret_cast<const char*>(p + 3 * n + 8 * line), _MM_HINT_T0);
  }
  /// Rows r0 = (x0 y0 z0 x1), r1 = (y1 z1 x2 y2), r2 = (z2 x3 y3 z3)
  /// transposed into lanes (x0..3), (y0..3), (z0..3).
  __attribute__((target("avx2,fma"))) inline void load4(std::size_t n, __m256d* out) const
  {
    const double* v = p + 3 * n;
    const __m256d r0 = _mm256_loadu_pd(v), r1 = _mm256_loadu_pd(v + 4), r2 = _mm256_loadu_pd(v + 8);
    out[0] = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(r0, r1, 0x4), r2, 0x2), 0x6C);
    out[1] = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(r0, r1, 0x9), r2, 0x4), 0xB1);
    out[2] = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(r0, r1, 0x2), r2, 0x9), 0xC6);
  }
  /// 24 values r0 = v[0..8), r1 = v[8..16), r2 = v[16..24); two two-source
  /// permutes per coordinate gather (x of vertices 0..7) etc.
  __attribute__((target("avx512f"))) inline void load8(std::size_t n, __m512d* out) const
  {
    // Stage 1 picks from (r0, r1) (indices 0..15), stage 2 adds r2 (8..15 = r2[0..8)).
    const __m512i x01 = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), x2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13);
    const __m512i y01 = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), y2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14);
    const __m512i z01 = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), z2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15);
    const double* v = p + 3 * n;
    const __m512d r0 = _mm512_loadu_pd(v), r1 = _mm512_loadu_pd(v + 8), r2 = _mm512_loadu_pd(v + 16);
    out[0] = _mm512_permutex2var_pd(_mm512_permutex2var_pd(r0, x01, r1), x2, r2);
    out[1] = _mm512_permutex2var_pd(_mm512_permutex2var_pd(r0, y01, r1), y2, r2);
    out[2] = _mm512_permutex2var_pd(_mm512_permutex2var_pd(r0, z01, r1), z2, r2);
  }
#endif
};

/// Coordinates stored by coordinate: x[n], y[n], z[n].
struct ByCoordinate
{
  const double* x;
  const double* y;
  const double* z;
  void vertex(std::size_t n, double* out) const
  {
    out[0] = x[n];
    out[1] = y[n];
    out[2] = z[n];
  }
  ByCoordinate from(std::size_t n) const { return { x + n, y + n, z + n }; }
#if defined(DRB_VERTEX_KERNELS_AVX2)
  __attribute__((always_inline)) inline void prefetch(std::size_t n) const
  {
    for (const double* c : { x, y, z })
      _mm_prefetch(reinterpret_cast<const char*>(c + n), _MM_HINT_T0);
  }
  __attribute__((target("avx2,fma"))) inline void load4(std::size_t n, __m256d* out) const
  {
    out[0] = _mm256_loadu_pd(x + n), out[1] = _mm256_loadu_pd(y + n), out[2] = _mm256_loadu_pd(z + n);
  }
  __attribute__((target("avx512f"))) inline void load8(std::size_t n, __m512d* out) const
  {
    out[0] = _mm512_loadu_pd(x + n), out[1] = _mm512_loadu_pd(y + n), out[2] = _mm512_loadu_pd(z + n);
  }
#endif
};

/// Vertex n is vertex index[n] of `layout` (indices already validated).
template <typename Layout>
struct Gathered
{
  Layout layout;
  const std::uint32_t* index;
  void vertex(std::size_t n, double* out) const { layout.vertex(index[n], out); }
  Gathered from(std::size_t n) const { return { layout, index + n }; }
#if defined(DRB_VERTEX_KERNELS_AVX2)
  __attribute__((always_inline)) inline void prefetch(std::size_t) const {}
  template <int N>
  void gather(std::size_t n, double (&xyz)[3][N]) const
  {
    for (int m = 0; m < N; ++m)
    {
      double p[3];
      vertex(n + static_cast<std::size_t>(m), p);
      for (int a = 0; a < 3; ++a)
        xyz[a][m] = p[a];
    }
  }
  __attribute__((target("avx2,fma"))) inline void load4(std::size_t n, __m256d* out) const
  {
    double xyz[3][4];
    gather(n, xyz);
    for (int a = 0; a < 3; ++a)
      out[a] = _mm256_loadu_pd(xyz[a]);
  }
  __attribute__((target("avx512f"))) inline void load8(std::size_t n, __m512d* out) const
  {
    double xyz[3][8];
    gather(n, xyz);
    for (int a = 0; a < 3; ++a)
      out[a] = _mm512_loadu_pd(xyz[a]);
  }
#endif
};

// ---- the sums ---------------------------------------------------------------

/// Adds vertices [begin, end) one at a time: the tails and the portable path.
template <typename Vertices>
void addGradientSumsScalar(const Vertices& vertices, const ByVertex& gradients, std::size_t begin, std::size_t end,
                           GradientSums12& sums)
{
  for (std::size_t n = begin; n < end; ++n)
  {
    double p[3], g[3];
    vertices.vertex(n, p);
    gradients.vertex(n, g);
    for (int a = 0; a < 3; ++a)
    {
      for (int b = 0; b < 3; ++b)
        sums[3 * a + b] += g[a] * p[b];
      sums[9 + a] += g[a];
    }
  }
}

#if defined(DRB_VERTEX_KERNELS_AVX2)
/// Sum of the lanes of a register, as ((0 + 2) + (1 + 3)) for 4 lanes and
/// ((0 + 4) + (2 + 6)) + ((1 + 5) + (3 + 7)) for 8: halves added, then again.
inline double laneSum(__m128d v)
{
  return _mm_cvtsd_f64(_mm_add_sd(v, _mm_unpackhi_pd(v, v)));
}
__attribute__((target("avx"))) inline double laneSum(__m256d v)
{
  return laneSum(_mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1)));
}
/// (The zero-masked extracts say the same as the plain ones, without GCC
/// 12's false -Wuninitialized on those.)
__attribute__((target("avx512f"))) inline double laneSum(__m512d v)
{
  return laneSum(_mm256_add_pd(_mm512_maskz_extractf64x4_pd(0xFF, v, 0), _mm512_maskz_extractf64x4_pd(0xFF, v, 1)));
}

/// The wide kernels: vertices [0, W floor(count / W)), W per register (8
/// for AVX-512F, 4 for AVX2 + FMA), one FMA per product, the lanes added by
/// laneSum at the end; returns the vertices done. One body for both widths:
/// GCC compiles a function for one target only and refuses to inline
/// target-specific code into a template without that target, so the body is
/// a macro instantiated once per target. The prefetch is issued once per
/// 8 vertices (one line of each coordinate array).
#define DRB_GRADIENT_SUMS_KERNEL(NAME, TARGET, REG, WIDTH, SETZERO, FMADD, ADD, LOAD)                               \
  template <typename Vertices>                                                                                    \
  __attribute__((target(TARGET))) std::size_t NAME(const Vertices& vertices, const ByVertex& gradients,           \
                                                   std::size_t count, GradientSums12& sums)                       \
  {                                                                                                               \
    REG acc[12]; /* W row-major, then force */                                                                    \
    _Pragma("GCC unroll 12") for (REG& a : acc) a = SETZERO();                                                    \
    std::size_t n = 0;                                                                                            \
    for (; n + WIDTH <= count; n += WIDTH)                                                                        \
    {                                                                                                             \
      if (n % 8 == 0 && n + kPrefetchVertices + 8 <= count)                                                       \
      {                                                                                                           \
        gradients.prefetch(n + kPrefetchVertices);                                                                \
        vertices.prefetch(n + kPrefetchVertices);                                                                 \
      }                                                                                                           \
      REG G[3], P[3];                                                                                             \
      gradients.LOAD(n, G);                                                                                       \
      vertices.LOAD(n, P);                                                                                        \
      /* Fixed-count loops are unrolled so that acc lives in registers. */                                        \
      _Pragma("GCC unroll 3") for (int a = 0; a < 3; ++a)                                                         \
      {                                                                                                           \
        _Pragma("GCC unroll 3") for (int b = 0; b < 3; ++b) acc[3 * a + b] = FMADD(G[a], P[b], acc[3 * a + b]);   \
        acc[9 + a] = ADD(acc[9 + a], G[a]);                                                                       \
      }                                                                                                           \
    }                                                                                                             \
    _Pragma("GCC unroll 12") for (int k = 0; k < 12; ++k) sums[k] += laneSum(acc[k]);                             \
    return n;                                                                                                     \
  }

DRB_GRADIENT_SUMS_KERNEL(addGradientSumsAvx512, "avx512f", __m512d, 8, _mm512_setzero_pd, _mm512_fmadd_pd,
                         _mm512_add_pd, load8)
DRB_GRADIENT_SUMS_KERNEL(addGradientSumsAvx2, "avx2,fma", __m256d, 4, _mm256_setzero_pd, _mm256_fmadd_pd,
                         _mm256_add_pd, load4)
#undef DRB_GRADIENT_SUMS_KERNEL
#endif

/// The 12 sums over vertices [0, count): the widest path the CPU has, then
/// the rest one by one.
template <typename Vertices>
GradientSums12 gradientSums(const Vertices& vertices, const ByVertex& gradients, std::size_t count)
{
  GradientSums12 sums{};
  std::size_t done = 0;
#if defined(DRB_VERTEX_KERNELS_AVX2)
  if (cpuHasAvx512f())
    done = addGradientSumsAvx512(vertices, gradients, count, sums);
  else if (cpuHasAvx2Fma())
    done = addGradientSumsAvx2(vertices, gradients, count, sums);
#endif
  addGradientSumsScalar(vertices, gradients, done, count, sums);
  return sums;
}

/// The 12 sums over vertices [0, count) cut into `chunks` contiguous chunks,
/// each on its own thread (the calling one included; a chunk whose thread
/// cannot start runs here), added in chunk order: for a given count, chunk
/// count and CPU path the result is always the same.
template <typename Vertices>
GradientSums12 gradientSumsInChunks(const Vertices& vertices, const double* gradients, std::size_t count,
                                    std::size_t chunks)
{
  const ByVertex g{ gradients };
  GradientSums12 total{};
  auto addInOrder = [&total](const GradientSums12* partial, std::size_t n) {
    for (std::size_t c = 0; c < n; ++c)
      for (int k = 0; k < 12; ++k)
        total[k] += partial[c][k];
  };
  if (chunks <= 1)  // no allocation, no thread
  {
    const GradientSums12 all = gradientSums(vertices, g, count);
    addInOrder(&all, 1);
    return total;
  }
  std::vector<GradientSums12> partial(chunks);
  auto chunkBegin = [&](std::size_t c) { return count * c / chunks; };
  auto run = [&](std::size_t c) {
    const std::size_t begin = chunkBegin(c);
    partial[c] = gradientSums(vertices.from(begin), g.from(begin), chunkBegin(c + 1) - begin);
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
  addInOrder(partial.data(), chunks);
  return total;
}
}  // namespace detail
}  // namespace diff_rigid_body
