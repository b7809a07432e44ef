// requireFinite and requireFiniteResults: the check every request's inputs and
// every answer pass through, at memory speed (one add per 2 values with SSE2,
// per 4 with AVX where the CPU has it; chosen once at load time).
#include <cmath>
#include <cstring>
#include <sstream>

#include "diff_rigid_body/services/scene_queries.h"
#include "services/finite_values.h"
#include "services/request_checks.h"
#include "services/request_layout.h"

namespace diff_rigid_body
{
#ifdef DRB_FINITE_VALUES_X86
namespace detail
{
namespace
{
/// chain += the Vector at `values` (an unaligned load).
template <typename Vector>
[[gnu::always_inline]] inline void addLoaded(Vector& chain, const double* values)
{
  Vector next;
  std::memcpy(&next, values, sizeof(Vector));
  chain += next;
}

/// The sum of `values` in four chains of Vector (GCC vector extensions, of
/// Vector's lanes): 4 x lanes values per step, then up to three whole
/// vectors, then fewer than `lanes` values one by one, so that a short array
/// (a frame's 12-value pose) is a few independent adds, not one per value.
/// Inlined into each caller, whose target (SSE2, AVX) sets the instructions.
template <typename Vector>
[[gnu::always_inline]] inline double sumInChains(const double* values, std::size_t count)
{
  constexpr std::size_t lanes = sizeof(Vector) / sizeof(double);
  Vector a = {}, b = {}, c = {}, d = {};
  std::size_t i = 0;
  for (; i + 4 * lanes <= count; i += 4 * lanes)
  {
    addLoaded(a, values + i);
    addLoaded(b, values + i + lanes);
    addLoaded(c, values + i + 2 * lanes);
    addLoaded(d, values + i + 3 * lanes);
  }
  for (Vector* chain : { &a, &b, &c })
    if (i + lanes <= count)
    {
      addLoaded(*chain, values + i);
      i += lanes;
    }
  const Vector total = (a + b) + (c + d);
  double sum = 0.0;
  for (std::size_t l = 0; l < lanes; ++l)
    sum += total[l];
  for (; i < count; ++i)
    sum += values[i];
  return sum;
}

typedef double Lanes2 __attribute__((vector_size(16)));
typedef double Lanes4 __attribute__((vector_size(32)));
}  // namespace

double sumSse2(const double* values, std::size_t count)
{
  return sumInChains<Lanes2>(values, count);
}

__attribute__((target("avx"))) double sumAvx(const double* values, std::size_t count)
{
  return sumInChains<Lanes4>(values, count);
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
    if (!values->empty())  // an answer leaves the fields it was not asked for empty
      sum += sumOf(values->data(), values->size());
  if (std::isfinite(sum))
    return;
  for (const auto& [field, values] : results)
    requireFinite(values->data(), values->size(), field);
}
}  // namespace detail
}  // namespace diff_rigid_body
