// Running third-party code that may crash, hang or exhaust memory on hostile
// input (assimp's importers) in a child process, so that the caller gets an
// error instead of losing its own process.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>

namespace diff_rigid_body
{
/// The child process did not return a result: it was killed by a signal
/// (e.g. SIGSEGV inside the importer, or SIGKILL from the out-of-memory
/// killer), exited abnormally, or ran past its time limit.
class ChildProcessFailure : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Runs `work` in a forked child process and returns the bytes it returned.
/// A std::exception thrown by `work` is rethrown here as std::runtime_error
/// with its message. The child starts with the default action for SIGSEGV,
/// SIGBUS, SIGFPE, SIGILL and SIGABRT (no handler of the parent's runs in it)
/// and ends with _exit, so it flushes and destroys nothing of the parent's.
/// After `timeout` the child is killed and ChildProcessFailure thrown. The
/// child may grow its address space by `memory_limit` bytes beyond what it
/// inherits (RLIMIT_AS; not applied under AddressSanitizer, whose shadow
/// memory needs an unlimited address space), so that an importer that
/// allocates without bound fails there with std::bad_alloc.
/// Only the calling thread exists in the child: `work` must not wait for
/// other threads of the parent.
std::string runInChildProcess(const std::function<std::string()>& work, std::chrono::milliseconds timeout,
                              std::size_t memory_limit);

}  // namespace diff_rigid_body
