// The state file on disk: atomic, durable writes and bounded reads
// (include/diff_rigid_body/state/state_file.h; the text in state_file_format.cpp).
#include <array>
#include <cerrno>
#include <cstring>
#include <vector>

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "diff_rigid_body/state/state_file.h"

namespace diff_rigid_body
{
namespace
{
[[noreturn]] void fail(const std::string& message)
{
  throw StateFileError(message);
}

std::string systemError(const std::string& what, int error)
{
  return what + ": " + std::strerror(error);
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
  const std::size_t limit = maxStateFileSize(scene);
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
