#include "mass/child_process.h"

#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace diff_rigid_body
{
namespace
{
// The child's answer on the pipe: one status byte, then the payload (the
// result, or the message of the exception `work` threw).
constexpr char kResult = 'R';
constexpr char kException = 'E';

void writeAll(int fd, const char* data, std::size_t size)
{
  while (size > 0)
  {
    const ssize_t written = ::write(fd, data, size);
    if (written < 0 && errno == EINTR)
      continue;
    if (written <= 0)
      return;
    data += written;
    size -= static_cast<std::size_t>(written);
  }
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

// Caps the address space at its current size (from /proc/self/statm, in
// pages) plus `extra` bytes.
void limitAddressSpace(std::size_t extra)
{
  if (kAddressSanitizer)
    return;
  std::size_t pages = 0;
  if (std::FILE* statm = std::fopen("/proc/self/statm", "r"))
  {
    if (std::fscanf(statm, "%zu", &pages) != 1)
      pages = 0;
    std::fclose(statm);
  }
  const rlim_t limit = static_cast<rlim_t>(pages) * static_cast<rlim_t>(::sysconf(_SC_PAGESIZE)) + extra;
  const rlimit address_space{ limit, limit };
  ::setrlimit(RLIMIT_AS, &address_space);
}

[[noreturn]] void runChild(int fd, const std::function<std::string()>& work, std::size_t memory_limit)
{
  for (int signal_number : { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT })
    ::signal(signal_number, SIG_DFL);
  limitAddressSpace(memory_limit);
  std::string answer;
  try
  {
    answer = kResult + work();
  }
  catch (const std::exception& e)
  {
    answer = kException + std::string(e.what());
  }
  writeAll(fd, answer.data(), answer.size());
  ::close(fd);
  ::_exit(0);
}

// Reads the pipe until EOF or the deadline; false on timeout.
bool readUntilEof(int fd, std::chrono::steady_clock::time_point deadline, std::string& out)
{
  char buffer[65536];
  for (;;)
  {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0)
      return false;
    pollfd ready{ fd, POLLIN, 0 };
    const int polled = ::poll(&ready, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (polled < 0 && errno != EINTR)
      return true;
    if (polled <= 0)
      continue;
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR)
      continue;
    if (got <= 0)
      return true;
    out.append(buffer, static_cast<std::size_t>(got));
  }
}

std::string describeStatus(int status)
{
  if (WIFSIGNALED(status))
  {
    const int number = WTERMSIG(status);
    return "was killed by signal " + std::to_string(number) + " (" + ::strsignal(number) + ")";
  }
  return "exited with status " + std::to_string(WEXITSTATUS(status));
}
}  // namespace

std::string runInChildProcess(const std::function<std::string()>& work, std::chrono::milliseconds timeout,
                              std::size_t memory_limit)
{
  int fds[2];
  if (::pipe(fds) != 0)
    throw ChildProcessFailure(std::string("cannot create a pipe: ") + std::strerror(errno));
  const pid_t child = ::fork();
  if (child < 0)
  {
    ::close(fds[0]);
    ::close(fds[1]);
    throw ChildProcessFailure(std::string("cannot fork: ") + std::strerror(errno));
  }
  if (child == 0)
  {
    ::close(fds[0]);
    runChild(fds[1], work, memory_limit);
  }
  ::close(fds[1]);
  std::string answer;
  const bool finished = readUntilEof(fds[0], std::chrono::steady_clock::now() + timeout, answer);
  ::close(fds[0]);
  if (!finished)
    ::kill(child, SIGKILL);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR)
  {
  }
  if (!finished)
    throw ChildProcessFailure("did not finish within " + std::to_string(timeout.count() / 1000) + " s and was killed");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || answer.empty())
    throw ChildProcessFailure(describeStatus(status));
  if (answer[0] == kException)
    throw std::runtime_error(answer.substr(1));
  return answer.substr(1);
}

}  // namespace diff_rigid_body
