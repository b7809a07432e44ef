// The durable state file of rigid_body_server (~state_file): the last
// accepted state of every body, written atomically and durably, and read
// back whole or not at all. ROS-free; the node only calls these functions.
//
// Format (text, one record per line, '\n' line ends, version 1):
//
//   diff_rigid_body state file v1
//   fingerprint <16 hex digits>            sceneFingerprint() of the scene
//   bodies <n>
//   body <name> <x0> ... <x_{d-1}>          n lines, scene order, d = the body's dofs
//   end <n> crc32 <8 hex digits>
//
//   - <name> is the body name percent-encoded: every byte outside '!'..'~',
//     and '%' itself, becomes %XX (upper-case hex), so a name is one token;
//   - <xi> is the body's x (SceneState): q = (phi, theta, psi, tx, ty, tz)
//     for a free body (the 6 values of version 1's lines), the coordinates of
//     articulated_body.h for an articulated one; C99 hexadecimal floats
//     ("%a", e.g. 0x1.921fb54442d18p+1), which round-trip bit for bit;
//   - the CRC-32 (IEEE 802.3, as zlib's crc32) covers every byte before the
//     "end" line.
//
// A file is accepted only if every line parses, the counts agree, the CRC
// matches, nothing follows the trailer, every value is finite, the
// fingerprint and the body names equal the scene's, and every body line has
// its body's dofs. Anything else is a
// StateFileError saying what was wrong; there is no partial read.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "diff_rigid_body/exceptions.h"
#include "diff_rigid_body/services/scene_queries.h"

namespace diff_rigid_body
{
/// A state file that cannot be read, parsed, matched to the scene or written.
class StateFileError : public Error
{
public:
  using Error::Error;
};

/// Largest state file that is read [bytes]: 64 KiB plus 4 KiB per body of the
/// scene. A bigger file is refused before it is read.
std::size_t maxStateFileSize(std::size_t body_count);

/// Largest state file read for `scene`: maxStateFileSize(bodies) plus 32
/// bytes for every coordinate beyond 6 of a body (a hex float and a space
/// take at most 25), so that what writeStateFile writes is always read back.
std::size_t maxStateFileSize(const Scene& scene);

/// 64-bit FNV-1a over what the state means for a scene: the fixed frame and,
/// per body in order, its name, mass, inertia, COM offset and body-frame
/// vertices (their IEEE bits), and for an articulated body its tree: per
/// segment its link, parent, joint (name, motion, origin, axis, coordinate,
/// mimic factors), mass properties and vertex range, then its vertices and
/// joint names. A scene of free bodies has version 1's fingerprint. A
/// different value means a state saved for another scene would put the
/// bodies somewhere else.
std::uint64_t sceneFingerprint(const Scene& scene);

/// CRC-32 (IEEE 802.3 polynomial, reflected, as zlib's crc32()).
std::uint32_t crc32(const std::string& bytes);

/// The file text for `state` (one x per scene body, in scene order).
/// Throws StateFileError if the sizes (bodies, or a body's dofs) differ or a
/// value is not finite.
std::string formatStateFile(const Scene& scene, const SceneState& state);

/// The state in `text`, checked against `scene` (see the header comment).
/// Throws StateFileError naming the line and what was wrong.
SceneState parseStateFile(const std::string& text, const Scene& scene);

/// Reads and parses the state file at `path`; std::nullopt if there is no
/// file. Throws StateFileError if it exists but cannot be read, is too large,
/// or is not a valid state for `scene`.
std::optional<SceneState> readStateFile(const std::string& path, const Scene& scene);

/// Writes `state` to `path` durably and atomically: a temporary file in the
/// same folder is written, fsync'ed, renamed over `path`, and the folder is
/// fsync'ed. When this returns, the new file survives a crash of the process
/// or the machine; when it throws StateFileError (naming the path and the
/// system error), `path` holds either its old or its new contents, never a
/// mix, and no temporary file is left behind.
void writeStateFile(const std::string& path, const Scene& scene, const SceneState& state);

/// Removes the temporary files "<path>.tmp.XXXXXX" that writeStateFile
/// leaves behind when its process is killed mid-write; call it on start,
/// when no other writer of `path` runs. Returns how many were removed.
std::size_t removeStaleTemporaryFiles(const std::string& path);

/// Moves an unusable state file aside to "<path>.bad" (replacing an older
/// one) so that it is kept for inspection; returns the new path, or "" if
/// it could not be moved.
std::string setStateFileAside(const std::string& path);

}  // namespace diff_rigid_body
