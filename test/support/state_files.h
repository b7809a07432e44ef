// Helpers of the state-file tests (state_file.h): temporary folders, state
// comparison bit for bit, and edits of a file's text that keep or restore a
// valid trailer ("end <count> crc32 <8 hex digits>"), so that the checks
// behind the checksum are reached.
#pragma once

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include <dirent.h>
#include <stdlib.h>

#include <gtest/gtest.h>

#include "diff_rigid_body/state/state_file.h"

namespace drb_test
{
/// A new, empty folder under gtest's temporary directory: "<TempDir><name>_XXXXXX".
inline std::string tempFolder(const std::string& name)
{
  std::string folder = ::testing::TempDir() + name + "_XXXXXX";
  if (!::mkdtemp(folder.data()))
    throw std::runtime_error("mkdtemp failed for " + folder);
  return folder;
}

/// Entries of `folder` other than "." and "..".
inline std::size_t entriesIn(const std::string& folder)
{
  std::size_t n = 0;
  DIR* dir = ::opendir(folder.c_str());
  if (!dir)
    return 0;
  while (dirent* entry = ::readdir(dir))
    n += std::string(entry->d_name) != "." && std::string(entry->d_name) != "..";
  ::closedir(dir);
  return n;
}

/// Same number of bodies, each x of the same length and equal bit for bit
/// (-0 and NaN payloads count).
inline bool bitwiseEqual(const diff_rigid_body::SceneState& a, const diff_rigid_body::SceneState& b)
{
  if (a.size() != b.size())
    return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].size() != b[i].size() ||
        std::memcmp(a[i].data(), b[i].data(), sizeof(double) * static_cast<std::size_t>(a[i].size())) != 0)
      return false;
  return true;
}

/// The file's text before its trailer line.
inline std::string withoutTrailer(const std::string& text)
{
  return text.substr(0, text.rfind("end "));
}

/// `body` (a file without its trailer) with a correct trailer for `count` bodies.
inline std::string reseal(const std::string& body, std::size_t count)
{
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08x", diff_rigid_body::crc32(body));
  return body + "end " + std::to_string(count) + " crc32 " + crc + "\n";
}

/// `text` with the first `from` replaced by `to` (`from` must occur).
inline std::string replacedOnce(std::string text, const std::string& from, const std::string& to)
{
  const std::size_t at = text.find(from);
  if (at == std::string::npos)
    throw std::invalid_argument("replacedOnce: '" + from + "' does not occur");
  text.replace(at, from.size(), to);
  return text;
}
}  // namespace drb_test
