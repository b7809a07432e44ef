// DRB_EXPECT_THROWS_MESSAGE(expression, ErrorType, fragment...): a non-fatal
// gtest expectation that `expression` throws ErrorType (or a class derived
// from it) and that what() contains every fragment. The failure points at
// the line of the expectation and quotes the expression and the message.
//
// Its value is the message (empty when nothing of ErrorType was thrown), for
// the rare test that checks more than fragments.
//
// An expression with a top-level comma outside parentheses (a braced list
// such as f(a, { b, c })) must be wrapped in parentheses: ((f(a, { b, c }))).
#pragma once

#include <exception>
#include <string>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>

namespace drb_test
{
namespace detail
{
/// Runs `call`; records a failure at file:line unless it throws Error with
/// every fragment in what(). Another exception is a failure as well.
template <typename Error, typename Call>
std::string expectThrowsMessage(Call&& call, const std::vector<std::string>& fragments, const char* expression,
                                const char* error_type, const char* file, int line)
{
  std::string message;
  try
  {
    try
    {
      call();
    }
    catch (const Error& e)
    {
      message = e.what();
      for (const std::string& fragment : fragments)
        if (message.find(fragment) == std::string::npos)
          ADD_FAILURE_AT(file, line) << expression << " threw " << error_type << " '" << message
                                     << "', which does not contain '" << fragment << "'";
      return message;
    }
  }
  catch (const std::exception& e)
  {
    ADD_FAILURE_AT(file, line) << expression << " threw " << typeid(e).name() << " '" << e.what()
                               << "', expected " << error_type;
    return std::string();
  }
  ADD_FAILURE_AT(file, line) << expression << " did not throw, expected " << error_type;
  return message;
}
}  // namespace detail
}  // namespace drb_test

#define DRB_EXPECT_THROWS_MESSAGE(expression, ErrorType, ...)                                                     \
  ::drb_test::detail::expectThrowsMessage<ErrorType>([&] { static_cast<void>(expression); },                  \
                                                     std::vector<std::string>{ __VA_ARGS__ }, #expression, #ErrorType, \
                                                     __FILE__, __LINE__)
