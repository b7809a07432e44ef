// The vector sums behind requireFinite (finite_values.cpp), for its tests. An
// infinity or a NaN makes any sum it enters infinite or NaN, so a finite sum
// proves every value finite.
#pragma once

#include <cstddef>

#if defined(__x86_64__) && defined(__GNUC__)
#define DRB_FINITE_VALUES_X86 1

namespace diff_rigid_body
{
namespace detail
{
/// The sum of `values` in four 2-lane chains (SSE2, in every x86-64).
double sumSse2(const double* values, std::size_t count);
/// The sum of `values` in four 4-lane chains (AVX); only where cpuHasAvx().
double sumAvx(const double* values, std::size_t count);
/// Whether this CPU and its OS run AVX: requireFinite then uses sumAvx.
bool cpuHasAvx();
}  // namespace detail
}  // namespace diff_rigid_body
#endif
