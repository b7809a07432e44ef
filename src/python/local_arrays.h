// numpy arrays in and out of diff_rigid_body._local.
//
// Out: an answer's std::vector is moved to the heap and handed to numpy as
// the buffer of a 1-D array whose base is a capsule that frees it, so no
// value is copied. In: an InputArray is read through the buffer protocol
// (forcecast converts only what is not already C-contiguous of its dtype),
// and the core reads its float64 values in place (ArrayView); vertex index
// lists are copied into the std::vector the core takes.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>

#include "diff_rigid_body/services/array_view.h"

namespace diff_rigid_body
{
namespace python
{
namespace py = pybind11;

template <typename T>
using InputArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

/// A flat numpy array over `values`' own buffer (moved, not copied), freed
/// with the array.
template <typename T>
py::array_t<T> adopt(std::vector<T>&& values)
{
  if (values.empty())
    return py::array_t<T>(0);
  auto owned = std::make_unique<std::vector<T>>(std::move(values));
  std::vector<T>* raw = owned.get();
  py::capsule owner(raw, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  owned.release();  // the capsule frees it from here on
  return py::array_t<T>({ raw->size() }, { sizeof(T) }, raw->data(), owner);
}

/// Where an input array's values are: read under the GIL, used without it.
template <typename T>
struct Values
{
  const T* data = nullptr;
  std::size_t size = 0;

  explicit Values(const InputArray<T>& array) : data(array.data()), size(static_cast<std::size_t>(array.size())) {}
  ArrayView<T> view() const { return ArrayView<T>(data, size); }
  std::vector<T> vector() const { return std::vector<T>(data, data + size); }
};

}  // namespace python
}  // namespace diff_rigid_body
