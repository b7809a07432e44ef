// The state file's text: fingerprint, CRC, formatting and parsing
// (include/diff_rigid_body/state/state_file.h; file I/O in state_file_io.cpp).
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "services/body_names.h"
#include "diff_rigid_body/state/state_file.h"
#include "state/state_file_tokens.h"

namespace diff_rigid_body
{
namespace
{
const char* const kHeader = "diff_rigid_body state file v1";

[[noreturn]] void fail(const std::string& message)
{
  throw StateFileError(message);
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

void hashPoints(const Matrix3X<double>& points, Fnv1a& hash)
{
  hash.number(static_cast<std::uint64_t>(points.cols()));
  for (Eigen::Index i = 0; i < points.size(); ++i)
    hash.number(points.data()[i]);
}

// What places a tree's vertices at x: its segments, every joint (name, type,
// placement, axis, coordinate, mimic factors), the segments' mass properties,
// frames and vertex ranges, the vertices and the joint names in x order.
void hashTree(const BodyModel& body, Fnv1a& hash)
{
  hash.text("tree");
  hash.number(static_cast<std::uint64_t>(body.hasFreeRoot()));
  hash.number(static_cast<std::uint64_t>(body.segments.size()));
  for (const Segment& segment : body.segments)
  {
    hash.text(segment.link);
    hash.number(static_cast<std::uint64_t>(static_cast<std::int64_t>(segment.parent)));
    hash.text(segment.joint);
    hash.number(static_cast<std::uint64_t>(segment.joint_type));
    for (int i = 0; i < 9; ++i)
      hash.number(segment.placement_rotation(i / 3, i % 3));
    for (int i = 0; i < 3; ++i)
      hash.number(segment.placement_translation[i]);
    for (int i = 0; i < 3; ++i)
      hash.number(segment.axis[i]);
    const Dof& dof = body.dofs[static_cast<std::size_t>(segment.first_dof)];
    hash.number(static_cast<std::uint64_t>(static_cast<std::int64_t>(dof.coordinate)));
    hash.number(dof.multiplier);
    hash.number(segment.offset);
    hash.number(segment.inertia.mass);
    for (int i = 0; i < 3; ++i)
      hash.number(segment.inertia.com[i]);
    for (int i = 0; i < 9; ++i)
      hash.number(segment.inertia.inertia(i / 3, i % 3));
    for (int i = 0; i < 3; ++i)
      hash.number(segment.link_origin[i]);
    hash.number(static_cast<std::uint64_t>(segment.vertex_begin));
    hash.number(static_cast<std::uint64_t>(segment.vertex_count));
  }
  hashPoints(body.vertices, hash);
  hash.number(static_cast<std::uint64_t>(body.joint_names.size()));
  for (const std::string& name : body.joint_names)
    hash.text(name);
}
}  // namespace

using namespace detail;

std::size_t maxStateFileSize(std::size_t body_count)
{
  return 65536 + 4096 * body_count;
}

std::size_t maxStateFileSize(const Scene& scene)
{
  std::size_t extra_coordinates = 0;
  for (const BodyModel& body : scene.bodies)
    extra_coordinates += body.coordinates > 6 ? body.coordinates - 6 : 0;
  return maxStateFileSize(scene.bodies.size()) + 32 * extra_coordinates;
}

std::uint64_t sceneFingerprint(const Scene& scene)
{
  Fnv1a hash;
  hash.text(kHeader);
  hash.text(scene.fixed_frame);
  hash.number(static_cast<std::uint64_t>(scene.bodies.size()));
  for (const BodyModel& body : scene.bodies)
  {
    // A body of one free segment hashes as version 1 did (its files stay
    // valid): name, mass, inertia, COM offset, vertices; a tree adds its
    // segments, joints and coordinates instead of the vertices.
    hash.text(body.name);
    hash.number(body.mass());
    for (int i = 0; i < 9; ++i)
      hash.number(body.segments[0].inertia.inertia(i / 3, i % 3));
    const Eigen::Vector3d com_offset = body.rootComOffset();
    for (int i = 0; i < 3; ++i)
      hash.number(com_offset[i]);
    if (body.segments.size() > 1 || !body.hasFreeRoot())
    {
      hashTree(body, hash);
      continue;
    }
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
    const std::string& name = scene.bodies[i].name;
    const std::size_t dofs = scene.bodies[i].coordinates;
    if (static_cast<std::size_t>(state[i].size()) != dofs)
      fail("cannot save " + std::to_string(state[i].size()) + " values for body '" + name + "' of " +
           std::to_string(dofs) + " dofs");
    text += "body " + encodeName(name);
    for (std::size_t k = 0; k < dofs; ++k)
    {
      if (!std::isfinite(state[i][static_cast<Eigen::Index>(k)]))
        fail("cannot save a non-finite q[" + std::to_string(k) + "] of body '" + name + "'");
      text += " " + formatValue(state[i][static_cast<Eigen::Index>(k)]);
    }
    text += "\n";
  }
  text += "end " + std::to_string(state.size()) + " crc32 " + hex(crc32(text), 8) + "\n";
  return text;
}

namespace
{
/// The lines of `text` (without their '\n') and where each starts, after
/// the checks that need no parsing: size, not empty, a final line end.
struct Lines
{
  std::vector<std::string> text;
  std::vector<std::size_t> starts;
};

Lines splitLines(const std::string& text, const Scene& scene)
{
  if (text.size() > maxStateFileSize(scene))
    fail("too large: " + std::to_string(text.size()) + " bytes, at most " +
         std::to_string(maxStateFileSize(scene)) + " for " + std::to_string(scene.bodies.size()) +
         " bodies");
  if (text.empty())
    fail("empty file");
  if (text.back() != '\n')
    fail("truncated: the last line has no line end (the file was cut short)");
  Lines lines;
  for (std::size_t start = 0; start < text.size();)
  {
    const std::size_t end = text.find('\n', start);
    lines.text.push_back(text.substr(start, end - start));
    lines.starts.push_back(start);
    start = end + 1;
  }
  return lines;
}

/// Checks the trailer "end <count> crc32 <crc>" against the bytes before it
/// and returns its count: a file cut short or damaged is reported as such,
/// before any of its contents is interpreted.
std::size_t checkTrailer(const std::string& text, const Lines& lines)
{
  const std::string& trailer = lines.text.back();
  const std::vector<std::string> tokens = splitTokens(trailer);
  if (tokens[0] != "end")
    fail("truncated: no 'end' line (the file was cut short or has trailing data)");
  std::size_t count = 0;
  std::uint64_t stored_crc = 0;
  if (tokens.size() != 4 || !parseCount(tokens[1], count) || tokens[2] != "crc32" ||
      !parseHex(tokens[3], 8, stored_crc))
    fail("line " + std::to_string(lines.text.size()) + ": expected 'end <count> crc32 <8 hex digits>', got '" +
         quoted(trailer) + "'");
  const std::uint32_t computed_crc = crc32(text.substr(0, lines.starts.back()));
  if (computed_crc != stored_crc)
    fail("checksum mismatch: the file is corrupt (crc32 " + hex(stored_crc, 8) + " stored, " +
         hex(computed_crc, 8) + " computed)");
  return count;
}

/// Lines 2 and 3, "fingerprint <hex>" and "bodies <count>", checked against
/// the number of body lines and the trailer's count. Returns the fingerprint.
std::uint64_t parseCounts(const Lines& lines, std::size_t end_count)
{
  if (lines.text.size() < 4)
    fail("truncated: expected a fingerprint and a bodies line");
  std::vector<std::string> tokens = splitTokens(lines.text[1]);
  std::uint64_t fingerprint = 0;
  if (tokens.size() != 2 || tokens[0] != "fingerprint" || !parseHex(tokens[1], 16, fingerprint))
    fail("line 2: expected 'fingerprint <16 hex digits>', got '" + quoted(lines.text[1]) + "'");
  tokens = splitTokens(lines.text[2]);
  std::size_t count = 0;
  if (tokens.size() != 2 || tokens[0] != "bodies" || !parseCount(tokens[1], count))
    fail("line 3: expected 'bodies <count>', got '" + quoted(lines.text[2]) + "'");
  const std::size_t body_lines = lines.text.size() - 4;
  if (count != body_lines || end_count != count)
    fail("body count mismatch: 'bodies " + std::to_string(count) + "', " + std::to_string(body_lines) +
         " body lines, 'end " + std::to_string(end_count) + "'");
  return fingerprint;
}

/// "expected 'body <name> <d hex floats>'" for a line of `d` values.
std::string expectedBodyLine(const std::string& where, std::size_t dofs, const std::string& line)
{
  return where + ": expected 'body <name> <" + std::to_string(dofs) + " hex floats>', got '" + quoted(line) + "'";
}

/// One "body <name> <hex floats>" line (line number `number`): any number
/// of values (at least one), checked against the body's dofs once the names
/// are known to be the scene's. `dofs` is the scene's for this line, for
/// the message of a line without values.
NamedState parseBodyLine(const std::string& line, std::size_t number, std::size_t dofs)
{
  const std::string where = "line " + std::to_string(number);
  const std::vector<std::string> tokens = splitTokens(line);
  if (tokens.size() < 3 || tokens[0] != "body")
    fail(expectedBodyLine(where, dofs, line));
  NamedState body;
  if (!decodeName(tokens[1], body.name) || body.name.empty())
    fail(where + ": malformed body name '" + quoted(tokens[1]) + "'");
  body.x.resize(static_cast<Eigen::Index>(tokens.size() - 2));
  for (std::size_t k = 0; k + 2 < tokens.size(); ++k)
  {
    double& value = body.x[static_cast<Eigen::Index>(k)];
    if (!parseValue(tokens[2 + k], value))
      fail(where + ": q[" + std::to_string(k) + "] of body '" + quoted(body.name) + "': not a hex float: '" +
           quoted(tokens[2 + k], 40) + "'");
    if (!std::isfinite(value))
      fail(where + ": q[" + std::to_string(k) + "] of body '" + quoted(body.name) + "': not finite");
  }
  return body;
}

/// "[a, b, ...]": at most 20 names, quoted.
std::string names(const std::vector<std::string>& list)
{
  return "[" + formatBodyNames(list.size(), [&list](std::size_t i) { return quoted(list[i]); }, 20) + "]";
}

/// Throws unless the file's bodies and fingerprint are the scene's.
void checkSameScene(const std::vector<std::string>& file_names, std::uint64_t fingerprint, const Scene& scene)
{
  std::vector<std::string> scene_names;
  for (const BodyModel& body : scene.bodies)
    scene_names.push_back(body.name);
  if (file_names != scene_names)
    fail("saved for other bodies: the file has " + names(file_names) + ", the scene has " + names(scene_names));
  const std::uint64_t expected = sceneFingerprint(scene);
  if (fingerprint != expected)
    fail("saved for another scene: fingerprint " + hex(fingerprint, 16) + ", the scene's is " + hex(expected, 16) +
         " (same bodies, but their mass properties, vertices or fixed frame differ)");
}
}  // namespace

SceneState parseStateFile(const std::string& text, const Scene& scene)
{
  const Lines lines = splitLines(text, scene);
  if (lines.text[0] != kHeader)
    fail("line 1: expected '" + std::string(kHeader) + "', got '" + quoted(lines.text[0]) + "'");
  const std::size_t count = checkTrailer(text, lines);
  const std::uint64_t fingerprint = parseCounts(lines, count);
  std::vector<std::string> file_names;
  SceneState state;
  state.reserve(count);
  for (std::size_t i = 0; i < count; ++i)
  {
    NamedState body = parseBodyLine(lines.text[i + 3], i + 4, i < scene.bodies.size() ? scene.bodies[i].coordinates : 6);
    file_names.push_back(std::move(body.name));
    state.push_back(std::move(body.x));
  }
  checkSameScene(file_names, fingerprint, scene);
  // Same bodies in the same order: each line has its body's dofs.
  for (std::size_t i = 0; i < count; ++i)
    if (static_cast<std::size_t>(state[i].size()) != scene.bodies[i].coordinates)
      fail(expectedBodyLine("line " + std::to_string(i + 4), scene.bodies[i].coordinates, lines.text[i + 3]));
  return state;
}

}  // namespace diff_rigid_body
