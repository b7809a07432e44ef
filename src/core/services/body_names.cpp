#include "services/body_names.h"

namespace diff_rigid_body
{
namespace detail
{
std::string formatBodyNames(std::size_t count, const std::function<std::string(std::size_t)>& name,
                            std::size_t limit)
{
  std::string out;
  for (std::size_t i = 0; i < count && i < limit; ++i)
    out += (out.empty() ? "" : ", ") + name(i);
  if (count > limit)
    out += ", ... (" + std::to_string(count) + " bodies)";
  return out;
}

std::string formatBodyNames(const std::vector<std::string>& names, std::size_t limit)
{
  return formatBodyNames(
      names.size(), [&names](std::size_t i) { return names[i]; }, limit);
}
}  // namespace detail
}  // namespace diff_rigid_body
