// A read-only view of contiguous values that a request passes in: a pointer
// and a count, owned by the caller for the duration of the call. The core's
// queries take request arrays as views, so that the node passes its message
// vectors (implicitly) and an in-process caller its own buffers (numpy's),
// neither copied.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <vector>

namespace diff_rigid_body
{
template <typename T>
class ArrayView
{
public:
  ArrayView() = default;
  ArrayView(const T* data, std::size_t size) : data_(size == 0 ? nullptr : data), size_(size) {}
  /// Implicit, so that a std::vector argument is passed as it is.
  ArrayView(const std::vector<T>& values) : ArrayView(values.data(), values.size()) {}
  /// For literal arguments ({0.1, 0.2}); the list lives until the call returns.
  ArrayView(std::initializer_list<T> values) : ArrayView(values.begin(), values.size()) {}

  const T* data() const { return data_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }

private:
  const T* data_ = nullptr;
  std::size_t size_ = 0;
};

/// A request's float64[] field: q, qdot, qddot, tau, gradients.
using DoubleView = ArrayView<double>;

}  // namespace diff_rigid_body
