// requireFinite and requireFiniteResults: the check every request's inputs and
// every answer pass through, at memory speed (one add per 2 values with SSE2,
// per 4 with AVX where the CPU has it; chosen once at load time).
#include <cmath>
#include <sstream>

#include "diff_rigid_body/services/scene_queries.h"
#include "services/finite_values.h"
#include "services/request_checks.h"
#include "services/request_layout.h"
#ifdef DRB_FINITE_VALUES_X86
#include <immintrin.h>
#endif

namespace diff_rigid_body
{
#ifdef DRB_FINITE_VALUES_X86
namespace detail
{
__attribute__((target("avx"))) double sumAvx(const double* values, std::size_t count)
{
  __m256d a = _mm256_setzero_pd(), b = a, c = a, d = a;
  std::size_t i = 0;
  for (; i + 16 <= count; i += 16)
  {
    a = _mm256_add_pd(a, _mm256_loadu_pd(values + i));
    b = _mm256_add_pd(b, _mm256_loadu_pd(values + i + 4));
    c = _mm256_add_pd(c, _mm256_loadu_pd(values + i + 8));
    d = _mm256_add_pd(d, _mm256_loadu_pd(values + i + 12));
  }
  for (; i + 4 <= count; i += 4)
    a = _mm256_add_pd(a, _mm256_loadu_pd(values + i));
  double lanes[4];
  _mm256_storeu_pd(lanes, _mm256_add_pd(_mm256_add_pd(a, b), _mm256_add_pd(c, d)));
  double sum = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
  for (; i < count; ++i)
    sum += values[i];
  return sum;
}

double sumSse2(const double* values, std::size_t count)
{
  __m128d a = _mm_setzero_pd(), b = a, c = a, d = a;
  std::size_t i = 0;
  for (; i + 8 <= count; i += 8)
  {
    a = _mm_add_pd(a, _mm_loadu_pd(values + i));
    b = _mm_add_pd(b, _mm_loadu_pd(values + i + 2));
    c = _mm_add_pd(c, _mm_loadu_pd(values + i + 4));
    d = _mm_add_pd(d, _mm_loadu_pd(values + i + 6));
  }
  double lanes[2];
  _mm_storeu_pd(lanes, _mm_add_pd(_mm_add_pd(a, b), _mm_add_pd(c, d)));
  double sum = lanes[0] + lanes[1];
  for (; i < count; ++i)
    sum += values[i];
  return sum;
}

bool cpuHasAvx()
{
  __builtin_cpu_init();  // this may run before libgcc's own initialiser
  return __builtin_cpu_supports("avx");
}
}  // namespace detail
#endif

namespace
{
/// Whether every value is finite, value by value.
bool eachFinite(const double* values, std::size_t count)
{
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      return false;
  return true;
}

#ifdef DRB_FINITE_VALUES_X86
// Zero (SSE2) until initialised, should another initialiser check values first.
const bool kHaveAvx = detail::cpuHasAvx();
#endif

/// The sum of `values`: finite when every value is, unless finite values
/// overflow it (allFinite then settles it value by value).
double sumOf(const double* values, std::size_t count)
{
#ifdef DRB_FINITE_VALUES_X86
  return kHaveAvx ? detail::sumAvx(values, count) : detail::sumSse2(values, count);
#else
  double sum = 0.0;
  for (std::size_t i = 0; i < count; ++i)
    sum += values[i];
  return sum;
#endif
}

bool allFinite(const double* values, std::size_t count)
{
  return std::isfinite(sumOf(values, count)) || eachFinite(values, count);
}

/// Refuses the first value of `values` that is not finite, by `field` and index.
[[noreturn]] void rejectNonFinite(const double* values, std::size_t count, const char* field)
{
  std::size_t i = 0;
  while (i + 1 < count && std::isfinite(values[i]))
    ++i;
  std::ostringstream why;
  why << field << "[" << i << "]: not finite (" << values[i] << ")";
  detail::reject(why.str());
}
}  // namespace

void requireFinite(const double* values, std::size_t count, const char* field)
{
  if (!allFinite(values, count))
    rejectNonFinite(values, count, field);
}

namespace detail
{
void requireFiniteResults(std::initializer_list<std::pair<const char*, const std::vector<double>*>> results)
{
  double sum = 0.0;
  for (const auto& [field, values] : results)
    sum += sumOf(values->data(), values->size());
  if (std::isfinite(sum))
    return;
  for (const auto& [field, values] : results)
    requireFinite(values->data(), values->size(), field);
}
}  // namespace detail
}  // namespace diff_rigid_body
