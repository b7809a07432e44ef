// What the vertex kernels are bounded by, measured in the same run: loops
// that only move the kernels' bytes, once, at each SIMD width the kernels
// dispatch to. And the backprop's sum forced onto one SIMD path, so that
// the AVX2 path is measured on a CPU that would pick AVX-512.
//
//   read floor  (backprop): the gradients (3 doubles per vertex, interleaved)
//               and the vertex columns x, y, z (1 double each) loaded once,
//               in the kernel's order (per step of W vertices: 3 loads of g,
//               one of each of x, y, z), added into 12 accumulators so that
//               no add latency limits the loads. 48 B per vertex.
//   write floor (vertex Jacobians): the answer's arrays (positions 3 and J 18
//               doubles per vertex) filled once with a value, with the kind of
//               store the kernel uses at that size: ordinary stores, or
//               non-temporal ones at or above kStreamingStoreBytes of J
//               (vertex_jacobian.h). 168 B per vertex.
// W = 2 (SSE2, the x86-64 baseline), 4 (AVX2) or 8 (AVX-512F) doubles.
#pragma once

#include <cstddef>
#include <cstdint>

#include "bench_common.h"
#include "diff_rigid_body/algorithm/free_body/vertex_columns.h"

#if defined(DRB_VERTEX_KERNELS_AVX2)
#include <immintrin.h>
#define DRB_BENCH_SIMD_PATHS 1
#endif

namespace drb_bench
{
/// A SIMD width the kernels dispatch to.
enum class SimdPath
{
  sse2,
  avx2,
  avx512
};

inline const char* pathName(SimdPath path)
{
  return path == SimdPath::avx512 ? "avx512" : path == SimdPath::avx2 ? "avx2" : "sse2";
}

/// true when this CPU can run `path`.
inline bool cpuHas(SimdPath path)
{
#if defined(DRB_BENCH_SIMD_PATHS)
  __builtin_cpu_init();
  if (path == SimdPath::avx512)
    return __builtin_cpu_supports("avx512f");
  if (path == SimdPath::avx2)
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return true;
#else
  return path == SimdPath::sse2;
#endif
}

#if defined(DRB_BENCH_SIMD_PATHS)
namespace floors
{
// One ISA per block of functions; V is the register, W its doubles.
#define DRB_FLOOR_FUNCTIONS(TARGET, V, W, LOADU, ADD, ZERO, STORE, STREAM, SET1)                                    \
  __attribute__((target(TARGET))) inline double read##W(const double* x, const double* y, const double* z,             \
                                                          const double* g, std::size_t count)                         \
  {                                                                                                                   \
    V acc[12];                                                                                                        \
    _Pragma("GCC unroll 12") for (V & a : acc) a = ZERO();                                                            \
    std::size_t n = 0;                                                                                                \
    for (; n + 2 * W <= count; n += 2 * W)                                                                            \
    {                                                                                                                 \
      _Pragma("GCC unroll 2") for (int h = 0; h < 2; ++h)                                                             \
      {                                                                                                               \
        const std::size_t m = n + W * h;                                                                              \
        const double* v = g + 3 * m;                                                                                  \
        acc[6 * h + 0] = ADD(acc[6 * h + 0], LOADU(v));                                                               \
        acc[6 * h + 1] = ADD(acc[6 * h + 1], LOADU(v + W));                                                           \
        acc[6 * h + 2] = ADD(acc[6 * h + 2], LOADU(v + 2 * W));                                                       \
        acc[6 * h + 3] = ADD(acc[6 * h + 3], LOADU(x + m));                                                           \
        acc[6 * h + 4] = ADD(acc[6 * h + 4], LOADU(y + m));                                                           \
        acc[6 * h + 5] = ADD(acc[6 * h + 5], LOADU(z + m));                                                           \
      }                                                                                                               \
    }                                                                                                                 \
    alignas(64) double lanes[W];                                                                                      \
    double sum = 0;                                                                                                   \
    _Pragma("GCC unroll 12") for (int k = 0; k < 12; ++k)                                                             \
    {                                                                                                                 \
      STORE(lanes, acc[k]);                                                                                           \
      for (int l = 0; l < W; ++l)                                                                                     \
        sum += lanes[l];                                                                                              \
    }                                                                                                                 \
    for (; n < count; ++n)                                                                                            \
      sum += ((g[3 * n] + g[3 * n + 1]) + g[3 * n + 2]) + ((x[n] + y[n]) + z[n]);                                     \
    return sum;                                                                                                       \
  }                                                                                                                   \
  __attribute__((target(TARGET))) inline void write##W(double* out, std::size_t count, double value, bool stream)     \
  {                                                                                                                   \
    const V v = SET1(value);                                                                                          \
    std::size_t i = 0;                                                                                                \
    for (; i < count && reinterpret_cast<std::uintptr_t>(out + i) % (8 * W) != 0; ++i)                                \
      out[i] = value;                                                                                                 \
    if (stream)                                                                                                       \
      for (; i + W <= count; i += W)                                                                                  \
        STREAM(out + i, v);                                                                                           \
    else                                                                                                              \
      for (; i + W <= count; i += W)                                                                                  \
        STORE(out + i, v);                                                                                            \
    for (; i < count; ++i)                                                                                            \
      out[i] = value;                                                                                                 \
  }

DRB_FLOOR_FUNCTIONS("sse2", __m128d, 2, _mm_loadu_pd, _mm_add_pd, _mm_setzero_pd, _mm_store_pd, _mm_stream_pd,
                    _mm_set1_pd)
DRB_FLOOR_FUNCTIONS("avx2", __m256d, 4, _mm256_loadu_pd, _mm256_add_pd, _mm256_setzero_pd, _mm256_store_pd,
                    _mm256_stream_pd, _mm256_set1_pd)
DRB_FLOOR_FUNCTIONS("avx512f", __m512d, 8, _mm512_loadu_pd, _mm512_add_pd, _mm512_setzero_pd, _mm512_store_pd,
                    _mm512_stream_pd, _mm512_set1_pd)
#undef DRB_FLOOR_FUNCTIONS
}  // namespace floors

/// The read floor of the backprop over `columns` and `gradients` on `path`.
inline double readFloor(SimdPath path, const drb::VertexColumns<double>& columns, const double* gradients)
{
  const std::size_t count = static_cast<std::size_t>(columns.rows());
  const double *x = columns.col(0).data(), *y = columns.col(1).data(), *z = columns.col(2).data();
  if (path == SimdPath::avx512)
    return floors::read8(x, y, z, gradients, count);
  if (path == SimdPath::avx2)
    return floors::read4(x, y, z, gradients, count);
  return floors::read2(x, y, z, gradients, count);
}

/// The write floor of positions + J for `count` vertices on `path`: 3 and 18
/// doubles per vertex, streamed when the kernel would stream (the same test
/// as vertexPositionsAndJacobians).
inline void writeFloor(SimdPath path, double* positions, double* jacobians, std::size_t count, double value)
{
  const bool stream = 18 * sizeof(double) * count >= drb::kStreamingStoreBytes;
  auto write = [&](double* out, std::size_t n) {
    if (path == SimdPath::avx512)
      floors::write8(out, n, value, stream);
    else if (path == SimdPath::avx2)
      floors::write4(out, n, value, stream);
    else
      floors::write2(out, n, value, stream);
  };
  write(jacobians, 18 * count);
  write(positions, 3 * count);
  if (stream)
    _mm_sfence();
}

/// dL/dq over all vertices by coordinate with the sum forced onto `path`
/// (sse2: the portable loop), as detail::gradientSums (backprop_sums.h)
/// does after its CPUID dispatch: what backpropagateVertexGradients
/// (vertex_columns.h) returns on a CPU whose best path is `path`.
inline Vector6d backpropColumnsOnPath(SimdPath path, const drb::BodyPose<double>& pose,
                                      const drb::VertexColumns<double>& columns, const double* gradients)
{
  const std::size_t count = static_cast<std::size_t>(columns.rows());
  const drb::detail::ByCoordinate vertices = drb::detail::byCoordinate(columns);
  const drb::detail::ByVertex g{ gradients };
  drb::detail::GradientSums12 sums{};
  std::size_t done = 0;
  if (path == SimdPath::avx512)
    done = drb::detail::addGradientSumsAvx512(vertices, g, count, sums);
  else if (path == SimdPath::avx2)
    done = drb::detail::addGradientSumsAvx2(vertices, g, count, sums);
  drb::detail::addGradientSumsScalar(vertices, g, done, count, sums);
  return drb::backpropFromSums(pose, sums);
}
#endif

}  // namespace drb_bench
