#include "state/state_file_tokens.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace diff_rigid_body
{
namespace detail
{
std::string hex(std::uint64_t value, int digits)
{
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%0*llx", digits, static_cast<unsigned long long>(value));
  return buffer;
}

bool parseHex(const std::string& token, std::size_t digits, std::uint64_t& value)
{
  if (token.size() != digits)
    return false;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value, 16);
  return result.ec == std::errc() && result.ptr == token.data() + token.size();
}

bool parseCount(const std::string& token, std::size_t& value)
{
  if (token.empty() || token.size() > 12 || (token.size() > 1 && token[0] == '0'))
    return false;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value, 10);
  return result.ec == std::errc() && result.ptr == token.data() + token.size();
}

std::string formatValue(double value)
{
  char buffer[64];
  std::size_t n = 0;
  if (std::signbit(value))
    buffer[n++] = '-';
  buffer[n++] = '0';
  buffer[n++] = 'x';
  const auto result = std::to_chars(buffer + n, buffer + sizeof buffer, std::fabs(value), std::chars_format::hex);
  return std::string(buffer, result.ptr);
}

bool parseValue(const std::string& token, double& value)
{
  const char* p = token.data();
  const char* end = p + token.size();
  const bool negative = p != end && *p == '-';
  if (negative)
    ++p;
  if (end - p < 3 || p[0] != '0' || (p[1] != 'x' && p[1] != 'X'))
    return false;
  p += 2;
  if (*p == '-' || *p == '+')
    return false;
  double magnitude = 0.0;
  const auto result = std::from_chars(p, end, magnitude, std::chars_format::hex);
  if (result.ec != std::errc() || result.ptr != end)
    return false;
  value = negative ? -magnitude : magnitude;
  return true;
}

std::string encodeName(const std::string& name)
{
  std::string out;
  for (unsigned char c : name)
  {
    if (c > ' ' && c <= '~' && c != '%')
      out += static_cast<char>(c);
    else
    {
      char escaped[4];
      std::snprintf(escaped, sizeof escaped, "%%%02X", c);
      out += escaped;
    }
  }
  return out;
}

bool decodeName(const std::string& token, std::string& name)
{
  name.clear();
  for (std::size_t i = 0; i < token.size(); ++i)
  {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c == '%')
    {
      std::uint64_t byte = 0;
      if (i + 2 >= token.size())
        return false;
      if (!parseHex(token.substr(i + 1, 2), 2, byte))
        return false;
      name += static_cast<char>(byte);
      i += 2;
    }
    else if (c > ' ' && c <= '~')
      name += static_cast<char>(c);
    else
      return false;
  }
  return true;
}

std::string quoted(const std::string& text, std::size_t limit)
{
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < limit; ++i)
  {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= ' ' && c <= '~')
      out += static_cast<char>(c);
    else
    {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", c);
      out += escaped;
    }
  }
  return text.size() > limit ? out + "..." : out;
}

std::vector<std::string> splitTokens(const std::string& line)
{
  std::vector<std::string> tokens;
  std::size_t start = 0;
  while (true)
  {
    const std::size_t space = line.find(' ', start);
    tokens.push_back(line.substr(start, space == std::string::npos ? std::string::npos : space - start));
    if (space == std::string::npos)
      return tokens;
    start = space + 1;
  }
}
}  // namespace detail
}  // namespace diff_rigid_body
