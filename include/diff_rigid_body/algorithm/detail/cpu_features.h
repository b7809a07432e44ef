// SIMD instruction sets of the vertex kernels: which ones the compiler can
// emit, and which ones the running CPU has.
//
// The package builds for the x86-64 baseline (no -march), so the binary runs
// on any x86-64: SSE2 is always there; AVX2 + FMA and AVX-512F kernels are
// compiled per function (target attribute) and chosen at run time from CPUID.
// Other targets take the portable loops.
#pragma once

#if defined(__SSE2__) && defined(__x86_64__)
#define DRB_VERTEX_KERNELS_SSE2 1
#include <emmintrin.h>
#if defined(__GNUC__)
#define DRB_VERTEX_KERNELS_AVX2 1
#include <immintrin.h>
#endif
#endif

namespace diff_rigid_body
{
namespace detail
{
#if defined(DRB_VERTEX_KERNELS_AVX2)
/// true when the CPU has AVX2 and FMA (checked once).
inline bool cpuHasAvx2Fma()
{
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return has;
}

/// true when the CPU has AVX-512F (checked once).
inline bool cpuHasAvx512f()
{
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f");
  }();
  return has;
}
#endif
}  // namespace detail
}  // namespace diff_rigid_body
