#include "bounded_request.h"

namespace diff_rigid_body
{
namespace detail
{
std::vector<std::string> topLevelFieldNames(const std::string& definition)
{
  std::vector<std::string> names;
  std::istringstream lines(definition);
  for (std::string line; std::getline(lines, line);)
  {
    if (line.rfind("===", 0) == 0)  // definitions of nested types follow
      break;
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string type, name;
    if (!(words >> type >> name) || line.find('=') != std::string::npos)  // empty, or a constant
      continue;
    names.push_back(name);
  }
  return names;
}
}  // namespace detail
}  // namespace diff_rigid_body
