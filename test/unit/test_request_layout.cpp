// The request-size checks of services/request_layout.h: K from q's length
// (dynamicsConfigurations) and the answer budget (withinBudget,
// checkDynamicsBudget), against exact integer arithmetic.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/services/scene_queries.h"
#include "services/request_layout.h"
#include "../support/expect_throws.h"

namespace drb = diff_rigid_body;

namespace
{
constexpr std::size_t kMax = std::numeric_limits<std::size_t>::max();

std::size_t configurationsOf(std::size_t D, std::size_t bodies, const std::vector<double>& q,
                             const std::vector<double>& qdot = {})
{
  const drb::DoubleView qdot_view(qdot);
  return drb::detail::dynamicsConfigurations(D, bodies, drb::DoubleView(q), { { "qdot", &qdot_view } });
}
}  // namespace

TEST(RequestLayout, ConfigurationsAreQsLengthOverD)
{
  for (std::size_t D : { 1, 6, 7, 35 })
    for (std::size_t K : { 1, 2, 3, 17 })
    {
      EXPECT_EQ(configurationsOf(D, 1, std::vector<double>(K * D, 0.5)), K) << D << " " << K;
      EXPECT_EQ(configurationsOf(D, 1, std::vector<double>(K * D), std::vector<double>(K * D)), K);
    }
  EXPECT_EQ(configurationsOf(6, 1, {}), 1u);  // empty: the current state
}

TEST(RequestLayout, RefusesAQOfNoWholeConfiguration)
{
  for (std::size_t size : { 1, 5, 7, 13 })
    DRB_EXPECT_THROWS_MESSAGE(configurationsOf(6, 2, std::vector<double>(size)), drb::InvalidArgumentError,
                              "q: expected a multiple of 6 values (the sum of the 2 bodies' dofs), or empty for the "
                              "current state, got " + std::to_string(size) + " values");
  // No body, or bodies without coordinates: any value is one too many.
  DRB_EXPECT_THROWS_MESSAGE(configurationsOf(6, 0, std::vector<double>(6)), drb::InvalidArgumentError, "q: expected");
  DRB_EXPECT_THROWS_MESSAGE(configurationsOf(0, 1, std::vector<double>(3)), drb::InvalidArgumentError, "q: expected");
  DRB_EXPECT_THROWS_MESSAGE(configurationsOf(6, 1, std::vector<double>(12), std::vector<double>(6)),
                            drb::InvalidArgumentError, "qdot: expected 12 values");
}

TEST(RequestLayout, BudgetIsTheExactProduct)
{
  const std::vector<std::size_t> values{ 0, 1, 2, 3, 7, 36, 1000, 4096, 65535, 1u << 20, kMax / 3, kMax / 2, kMax };
  for (std::size_t budget : { std::size_t{ 0 }, std::size_t{ 36 }, std::size_t{ 1000000 }, kMax / 2, kMax })
    for (std::size_t configurations : values)
      for (std::size_t per_configuration : values)
      {
        const unsigned __int128 product = static_cast<unsigned __int128>(configurations) * per_configuration;
        EXPECT_EQ(drb::detail::withinBudget(configurations, per_configuration, budget), product <= budget)
            << configurations << " x " << per_configuration << " against " << budget;
      }
  const std::size_t budget = drb::RequestLimits::kMaxMassMatrixDoubles;
  EXPECT_NO_THROW(drb::detail::checkDynamicsBudget(budget / 7, 7, false));
  DRB_EXPECT_THROWS_MESSAGE(drb::detail::checkDynamicsBudget(budget / 7 + 1, 7, false), drb::InvalidArgumentError,
                            "q: expected at most " + std::to_string(budget) + " answer values, got " +
                                std::to_string(budget / 7 + 1) + " configuration(s) x 7 values");
  EXPECT_NO_THROW(drb::detail::checkDynamicsBudget(kMax, 0, true));
}
