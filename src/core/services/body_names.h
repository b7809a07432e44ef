// The list of body names that error messages quote (not installed): unknown
// bodies in ~bodies and in requests, bodies of a state file.
#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace diff_rigid_body
{
namespace detail
{
/// "a, b, c": name(0) .. name(count - 1) joined by ", "; past `limit` names,
/// the rest is shown as ", ... (<count> bodies)".
std::string formatBodyNames(std::size_t count, const std::function<std::string(std::size_t)>& name,
                            std::size_t limit = std::numeric_limits<std::size_t>::max());

/// formatBodyNames over `names`, each shown as it is.
std::string formatBodyNames(const std::vector<std::string>& names,
                            std::size_t limit = std::numeric_limits<std::size_t>::max());
}  // namespace detail
}  // namespace diff_rigid_body
