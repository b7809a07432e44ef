// requireFinite, requireFiniteResults and both vector sums behind them (SSE2
// and, where the CPU has it, AVX) against std::isfinite value by value: every
// length across the vector blocks and their tails, a NaN or an infinity at
// every index, and finite values whose sum overflows.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "services/finite_values.h"
#include "services/request_layout.h"
#include "../support/expect_throws.h"

namespace drb = diff_rigid_body;

namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
const double kNaN = std::nan("");
constexpr std::size_t kLongest = 70;  // > 4 blocks of 16 (AVX) and 8 (SSE2), with tails

std::vector<double> ramp(std::size_t n)
{
  std::vector<double> values(n);
  for (std::size_t i = 0; i < n; ++i)
    values[i] = 0.25 * static_cast<double>(i) - 3.0;
  return values;
}
}  // namespace

TEST(FiniteValues, AcceptsFiniteValuesOfEveryLength)
{
  for (std::size_t n = 0; n <= kLongest; ++n)
  {
    const std::vector<double> values = ramp(n);
    EXPECT_NO_THROW(drb::requireFinite(values.data(), n, "x")) << n;
  }
}

TEST(FiniteValues, AcceptsFiniteValuesWhoseSumOverflows)
{
  for (std::size_t n = 2; n <= kLongest; ++n)
  {
    const std::vector<double> huge(n, std::numeric_limits<double>::max());
    EXPECT_NO_THROW(drb::requireFinite(huge.data(), n, "x")) << n;
    std::vector<double> both = huge;  // +max, -max, ...: partial sums overflow both ways
    for (std::size_t i = 1; i < n; i += 2)
      both[i] = -both[i];
    EXPECT_NO_THROW(drb::requireFinite(both.data(), n, "x")) << n;
  }
}

TEST(FiniteValues, RefusesEachNonFiniteValueByIndex)
{
  for (std::size_t n = 1; n <= kLongest; ++n)
    for (std::size_t at = 0; at < n; ++at)
      for (double bad : { kNaN, kInf, -kInf })
      {
        std::vector<double> values = ramp(n);
        values[at] = bad;
        DRB_EXPECT_THROWS_MESSAGE(drb::requireFinite(values.data(), n, "x"), drb::InvalidArgumentError,
                                  "x[" + std::to_string(at) + "]: not finite");
      }
}

TEST(FiniteValues, RefusesAnInfinityAmongOverflowingValues)
{
  std::vector<double> values(33, std::numeric_limits<double>::max());
  values[20] = -kInf;
  DRB_EXPECT_THROWS_MESSAGE(drb::requireFinite(values.data(), values.size(), "x"), drb::InvalidArgumentError,
                            "x[20]: not finite");
}

TEST(FiniteValues, ResultsNameTheFieldThatIsNotFinite)
{
  const std::vector<double> empty, small = ramp(5), large = ramp(40);
  EXPECT_NO_THROW(drb::detail::requireFiniteResults({ { "a", &empty }, { "b", &small }, { "c", &large } }));
  const std::vector<double> max(3, std::numeric_limits<double>::max());
  EXPECT_NO_THROW(drb::detail::requireFiniteResults({ { "a", &max }, { "b", &max } }));
  std::vector<double> bad = large;
  bad[37] = kNaN;
  DRB_EXPECT_THROWS_MESSAGE((drb::detail::requireFiniteResults({ { "a", &small }, { "c", &bad } })),
                            drb::InvalidArgumentError, "c[37]: not finite");
}

#ifdef DRB_FINITE_VALUES_X86
// Each kernel, whichever one this CPU makes requireFinite use: the sum of
// the ramp (exact in double: quarters) and a non-finite sum for a NaN or an
// infinity at any index.
TEST(FiniteValues, EachVectorSumSeesEveryValue)
{
  std::vector<std::pair<const char*, double (*)(const double*, std::size_t)>> kernels{ { "SSE2", drb::detail::sumSse2 } };
  if (drb::detail::cpuHasAvx())
    kernels.push_back({ "AVX", drb::detail::sumAvx });
  for (const auto& [name, sum] : kernels)
    for (std::size_t n = 0; n <= kLongest; ++n)
    {
      std::vector<double> values = ramp(n);
      const double exact = 0.125 * static_cast<double>(n) * static_cast<double>(n - 1) - 3.0 * static_cast<double>(n);
      EXPECT_EQ(sum(values.data(), n), exact) << name << " n=" << n;
      for (std::size_t at = 0; at < n; ++at)
        for (double bad : { kNaN, kInf, -kInf })
        {
          values = ramp(n);
          values[at] = bad;
          EXPECT_FALSE(std::isfinite(sum(values.data(), n))) << name << " n=" << n << " at " << at;
        }
    }
}
#endif
