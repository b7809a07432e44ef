// One row of the bad-input catalogue of docs/robustness.md
// (test/unit/test_bad_input_catalogue.cpp runs every row): an input, what
// must happen to it, and the run that tries it.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace drb_test
{
namespace catalogue
{
enum class Expect
{
  Refused,
  Accepted
};

struct Row
{
  std::string id;     ///< "U01": the line of the doc's table
  std::string input;  ///< what is tried (first column of the doc's table)
  Expect expect = Expect::Refused;
  std::string type;      ///< error class when refused, e.g. "SceneDescriptionError"
  std::string fragment;  ///< must be in the message (when refused)
  /// Runs the input; throws when refused. When accepted it returns a short
  /// description of the outcome (checked with EXPECT_* inside).
  std::function<std::string()> run;
};

// gtest prints a row by its id.
inline void PrintTo(const Row& row, std::ostream* out)
{
  *out << row.id;
}

/// The rows of the dynamics services (test_dynamics_catalogue.cpp).
std::vector<Row> dynamicsRows();

}  // namespace catalogue
}  // namespace drb_test
