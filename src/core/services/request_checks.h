// Refusal helpers shared by the SceneQueries sources (internal to the core).
#pragma once

#include <sstream>
#include <string>

#include "diff_rigid_body/exceptions.h"

namespace diff_rigid_body
{
namespace detail
{
[[noreturn]] inline void reject(const std::string& message)
{
  throw InvalidArgumentError(message);
}

/// "<field>: expected <expected>, got <got> values".
inline std::string sizeMismatch(const std::string& field, const std::string& expected, std::size_t got)
{
  std::ostringstream why;
  why << field << ": expected " << expected << ", got " << got << " values";
  return why.str();
}
}  // namespace detail
}  // namespace diff_rigid_body
