// This thread's scratch object of a type (SceneQueries' workspace cache, the
// frame requests' resolution): one per thread, so that concurrent requests on
// one SceneQueries never share them.
#pragma once

#include <memory>

namespace diff_rigid_body
{
namespace detail
{
/// This thread's T, created on its first use and destroyed when the thread
/// exits. After the first use it is one read of a thread_local pointer: a
/// pointer needs no initialisation guard, where a thread_local T with a
/// destructor is guarded (and in a shared library each thread_local access
/// may call __tls_get_addr).
template <typename T>
[[gnu::noinline]] T& threadScratch()
{
  thread_local T* scratch = nullptr;
  if (scratch != nullptr)
    return *scratch;
  thread_local std::unique_ptr<T> owner;  // destroys it at the thread's exit
  owner = std::make_unique<T>();
  scratch = owner.get();
  return *scratch;
}
}  // namespace detail
}  // namespace diff_rigid_body
