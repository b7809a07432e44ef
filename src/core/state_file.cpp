#include "diff_rigid_body/state_file.h"

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <vector>

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace diff_rigid_body
{
namespace
{
const char* const kHeader = "diff_rigid_body state file v1";

[[noreturn]] void fail(const std::string& message)
{
  throw StateFileError(message);
}

std::string systemError(const std::string& what, int error)
{
  return what + ": " + std::strerror(error);
}

// 64-bit FNV-1a.
class Fnv1a
{
public:
  void bytes(const void* data, std::size_t size)
  {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i)
    {
      hash_ ^= p[i];
      hash_ *= 0x100000001b3ULL;
    }
  }
  void number(std::uint64_t value) { bytes(&value, sizeof value); }
  void number(double value)
  {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    number(bits);
  }
  void text(const std::string& value)
  {
    number(static_cast<std::uint64_t>(value.size()));
    bytes(value.data(), value.size());
  }
  std::uint64_t value() const { return hash_; }

private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

std::string hex(std::uint64_t value, int digits)
{
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%0*llx", digits, static_cast<unsigned long long>(value));
  return buffer;
}

// Parses exactly `digits` lower- or upper-case hex digits.
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

// q value as a C99 hex float, "-0x1.8p+1"; independent of the C locale.
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

// A line or token quoted in an error: at most `limit` bytes, control and
// non-ASCII bytes as \xNN, so that the message stays one printable line.
std::string quoted(const std::string& text, std::size_t limit = 80)
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

std::string names(const std::vector<std::string>& list)
{
  std::string out;
  for (std::size_t i = 0; i < list.size() && i < 20; ++i)
    out += (out.empty() ? "" : ", ") + quoted(list[i]);
  if (list.size() > 20)
    out += ", ... (" + std::to_string(list.size()) + " bodies)";
  return "[" + out + "]";
}

// Writes all of `data` to `fd`, retrying partial writes and EINTR.
bool writeAll(int fd, const std::string& data)
{
  std::size_t done = 0;
  while (done < data.size())
  {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0)
    {
      if (errno == EINTR)
        continue;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::string folderOf(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos)
    return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}
}  // namespace

std::size_t maxStateFileSize(std::size_t body_count)
{
  return 65536 + 4096 * body_count;
}

std::uint64_t sceneFingerprint(const Scene& scene)
{
  Fnv1a hash;
  hash.text(kHeader);
  hash.text(scene.fixed_frame);
  hash.number(static_cast<std::uint64_t>(scene.bodies.size()));
  for (const SceneBody& scene_body : scene.bodies)
  {
    const RigidBody& body = scene_body.body;
    hash.text(body.name);
    hash.number(body.mass);
    for (int i = 0; i < 9; ++i)
      hash.number(body.inertia_body(i / 3, i % 3));
    for (int i = 0; i < 3; ++i)
      hash.number(body.com_offset[i]);
    hash.number(static_cast<std::uint64_t>(body.vertices.cols()));
    for (Eigen::Index v = 0; v < body.vertices.cols(); ++v)
      for (int i = 0; i < 3; ++i)
        hash.number(body.vertices(i, v));
  }
  return hash.value();
}

std::uint32_t crc32(const std::string& bytes)
{
  std::uint32_t crc = 0xffffffffu;
  for (unsigned char c : bytes)
  {
    crc ^= c;
    for (int bit = 0; bit < 8; ++bit)
      crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xffffffffu;
}

std::string formatStateFile(const Scene& scene, const SceneState& state)
{
  if (state.size() != scene.bodies.size())
    fail("cannot save a state of " + std::to_string(state.size()) + " bodies for a scene of " +
         std::to_string(scene.bodies.size()));
  std::string text = std::string(kHeader) + "\n";
  text += "fingerprint " + hex(sceneFingerprint(scene), 16) + "\n";
  text += "bodies " + std::to_string(state.size()) + "\n";
  for (std::size_t i = 0; i < state.size(); ++i)
  {
    text += "body " + encodeName(scene.bodies[i].body.name);
    for (int k = 0; k < 6; ++k)
    {
      if (!std::isfinite(state[i][k]))
        fail("cannot save a non-finite q[" + std::to_string(k) + "] of body '" + scene.bodies[i].body.name + "'");
      text += " " + formatValue(state[i][k]);
    }
    text += "\n";
  }
  text += "end " + std::to_string(state.size()) + " crc32 " + hex(crc32(text), 8) + "\n";
  return text;
}

SceneState parseStateFile(const std::string& text, const Scene& scene)
{
  if (text.size() > maxStateFileSize(scene.bodies.size()))
    fail("too large: " + std::to_string(text.size()) + " bytes, at most " +
         std::to_string(maxStateFileSize(scene.bodies.size())) + " for " + std::to_string(scene.bodies.size()) +
         " bodies");
  if (text.empty())
    fail("empty file");
  if (text.back() != '\n')
    fail("truncated: the last line has no line end (the file was cut short)");
  std::vector<std::string> lines;
  std::vector<std::size_t> line_starts;
  for (std::size_t start = 0; start < text.size();)
  {
    const std::size_t end = text.find('\n', start);
    lines.push_back(text.substr(start, end - start));
    line_starts.push_back(start);
    start = end + 1;
  }
  if (lines[0] != kHeader)
    fail("line 1: expected '" + std::string(kHeader) + "', got '" + quoted(lines[0]) + "'");

  // The trailer first: a file cut short or damaged is reported as such,
  // before any of its contents is interpreted.
  const std::string& trailer = lines.back();
  const std::string where_trailer = "line " + std::to_string(lines.size());
  const std::vector<std::string> end_tokens = splitTokens(trailer);
  if (end_tokens[0] != "end")
    fail("truncated: no 'end' line (the file was cut short or has trailing data)");
  std::size_t end_count = 0;
  std::uint64_t stored_crc = 0;
  if (end_tokens.size() != 4 || !parseCount(end_tokens[1], end_count) || end_tokens[2] != "crc32" ||
      !parseHex(end_tokens[3], 8, stored_crc))
    fail(where_trailer + ": expected 'end <count> crc32 <8 hex digits>', got '" + quoted(trailer) + "'");
  const std::uint32_t computed_crc = crc32(text.substr(0, line_starts.back()));
  if (computed_crc != stored_crc)
    fail("checksum mismatch: the file is corrupt (crc32 " + hex(stored_crc, 8) + " stored, " +
         hex(computed_crc, 8) + " computed)");

  if (lines.size() < 4)
    fail("truncated: expected a fingerprint and a bodies line");
  std::vector<std::string> tokens = splitTokens(lines[1]);
  std::uint64_t fingerprint = 0;
  if (tokens.size() != 2 || tokens[0] != "fingerprint" || !parseHex(tokens[1], 16, fingerprint))
    fail("line 2: expected 'fingerprint <16 hex digits>', got '" + quoted(lines[1]) + "'");
  tokens = splitTokens(lines[2]);
  std::size_t count = 0;
  if (tokens.size() != 2 || tokens[0] != "bodies" || !parseCount(tokens[1], count))
    fail("line 3: expected 'bodies <count>', got '" + quoted(lines[2]) + "'");
  const std::size_t body_lines = lines.size() - 4;
  if (count != body_lines || end_count != count)
    fail("body count mismatch: 'bodies " + std::to_string(count) + "', " + std::to_string(body_lines) +
         " body lines, 'end " + std::to_string(end_count) + "'");

  std::vector<std::string> file_names;
  SceneState state;
  state.reserve(count);
  for (std::size_t i = 0; i < count; ++i)
  {
    const std::string where = "line " + std::to_string(i + 4);
    tokens = splitTokens(lines[i + 3]);
    if (tokens.size() != 8 || tokens[0] != "body")
      fail(where + ": expected 'body <name> <6 hex floats>', got '" + quoted(lines[i + 3]) + "'");
    std::string name;
    if (!decodeName(tokens[1], name) || name.empty())
      fail(where + ": malformed body name '" + quoted(tokens[1]) + "'");
    Vector6<double> q;
    for (int k = 0; k < 6; ++k)
    {
      if (!parseValue(tokens[2 + k], q[k]))
        fail(where + ": q[" + std::to_string(k) + "] of body '" + quoted(name) + "': not a hex float: '" +
             quoted(tokens[2 + k], 40) + "'");
      if (!std::isfinite(q[k]))
        fail(where + ": q[" + std::to_string(k) + "] of body '" + quoted(name) + "': not finite");
    }
    file_names.push_back(name);
    state.push_back(q);
  }

  std::vector<std::string> scene_names;
  for (const SceneBody& body : scene.bodies)
    scene_names.push_back(body.body.name);
  if (file_names != scene_names)
    fail("saved for other bodies: the file has " + names(file_names) + ", the scene has " + names(scene_names));
  const std::uint64_t expected = sceneFingerprint(scene);
  if (fingerprint != expected)
    fail("saved for another scene: fingerprint " + hex(fingerprint, 16) + ", the scene's is " + hex(expected, 16) +
         " (same bodies, but their mass properties, vertices or fixed frame differ)");
  return state;
}

std::optional<SceneState> readStateFile(const std::string& path, const Scene& scene)
{
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0)
  {
    if (errno == ENOENT)
      return std::nullopt;
    fail("state file '" + path + "': " + systemError("cannot open", errno));
  }
  struct stat info;
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode))
  {
    ::close(fd);
    fail("state file '" + path + "': not a regular file");
  }
  const std::size_t limit = maxStateFileSize(scene.bodies.size());
  if (static_cast<std::uint64_t>(info.st_size) > limit)
  {
    ::close(fd);
    fail("state file '" + path + "': too large: " + std::to_string(info.st_size) + " bytes, at most " +
         std::to_string(limit) + " for " + std::to_string(scene.bodies.size()) + " bodies");
  }
  std::string text;
  std::array<char, 65536> buffer;
  while (text.size() <= limit)
  {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0)
    {
      if (errno == EINTR)
        continue;
      const int error = errno;
      ::close(fd);
      fail("state file '" + path + "': " + systemError("cannot read", error));
    }
    if (n == 0)
      break;
    text.append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(fd);
  try
  {
    return parseStateFile(text, scene);
  }
  catch (const StateFileError& e)
  {
    fail("state file '" + path + "': " + e.what());
  }
}

void writeStateFile(const std::string& path, const Scene& scene, const SceneState& state)
{
  const std::string text = formatStateFile(scene, state);
  std::string temp = path + ".tmp.XXXXXX";
  const int fd = ::mkstemp(temp.data());
  if (fd < 0)
    fail("state file '" + path + "': " + systemError("cannot create a temporary file in '" + folderOf(path) + "'",
                                                     errno));
  auto abandon = [&](const std::string& what, int error, bool close_fd) {
    if (close_fd)
      ::close(fd);
    ::unlink(temp.c_str());
    fail("state file '" + path + "': " + systemError(what, error));
  };
  if (!writeAll(fd, text))
    abandon("cannot write '" + temp + "'", errno, true);
  if (::fsync(fd) != 0)
    abandon("cannot fsync '" + temp + "'", errno, true);
  if (::close(fd) != 0)
    abandon("cannot close '" + temp + "'", errno, false);
  if (::rename(temp.c_str(), path.c_str()) != 0)
    abandon("cannot rename '" + temp + "' over it", errno, false);
  // The rename is only durable once the folder's entry is on disk.
  const std::string folder = folderOf(path);
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0)
    fail("state file '" + path + "': " + systemError("written, but cannot open its folder to fsync it", errno));
  if (::fsync(dir) != 0)
  {
    const int error = errno;
    ::close(dir);
    fail("state file '" + path + "': " + systemError("written, but cannot fsync its folder", error));
  }
  ::close(dir);
}

std::size_t removeStaleTemporaryFiles(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  const std::string prefix = (slash == std::string::npos ? path : path.substr(slash + 1)) + ".tmp.";
  const std::string folder = folderOf(path);
  DIR* dir = ::opendir(folder.c_str());
  if (!dir)
    return 0;
  std::vector<std::string> stale;
  while (const dirent* entry = ::readdir(dir))
  {
    const std::string name = entry->d_name;
    if (name.size() == prefix.size() + 6 && name.compare(0, prefix.size(), prefix) == 0)
      stale.push_back(folder + "/" + name);
  }
  ::closedir(dir);
  std::size_t removed = 0;
  for (const std::string& file : stale)
    removed += ::unlink(file.c_str()) == 0;
  return removed;
}

std::string setStateFileAside(const std::string& path)
{
  const std::string aside = path + ".bad";
  return ::rename(path.c_str(), aside.c_str()) == 0 ? aside : std::string();
}

}  // namespace diff_rigid_body
