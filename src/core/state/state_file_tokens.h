// The tokens of the state file (not installed): hex numbers, counts, hex
// floats, percent-encoded names, and quoting for error messages. See
// include/diff_rigid_body/state/state_file.h for the format.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace diff_rigid_body
{
namespace detail
{
/// `value` as `digits` lower-case hex digits.
std::string hex(std::uint64_t value, int digits);

/// Parses exactly `digits` lower- or upper-case hex digits.
bool parseHex(const std::string& token, std::size_t digits, std::uint64_t& value);

/// Parses a decimal count without sign or leading zeros (at most 12 digits).
bool parseCount(const std::string& token, std::size_t& value);

/// q value as a C99 hex float, "-0x1.8p+1"; independent of the C locale.
std::string formatValue(double value);

/// Parses a C99 hex float as formatValue writes it (optional '-', "0x").
bool parseValue(const std::string& token, double& value);

/// Every byte outside '!'..'~', and '%' itself, as %XX (upper-case hex).
std::string encodeName(const std::string& name);

/// Inverse of encodeName; false for a malformed token.
bool decodeName(const std::string& token, std::string& name);

/// A line or token quoted in an error: at most `limit` bytes, control and
/// non-ASCII bytes as \xNN, so that the message stays one printable line.
std::string quoted(const std::string& text, std::size_t limit = 80);

/// The tokens of a line separated by single spaces (empty tokens kept).
std::vector<std::string> splitTokens(const std::string& line);
}  // namespace detail
}  // namespace diff_rigid_body
