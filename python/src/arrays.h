// NumPy arrays over hapsim's own storage (zero-copy, read-only, keeping their owner alive) and
// small conversions from what Python passes in (docs/python.md#arrays-and-lifetimes).
#pragma once

#include "hapsim/core/error.h"
#include "hapsim/core/types.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstddef>
#include <string>
#include <vector>

namespace hapsim::python {

namespace py = pybind11;

/// A read-only view of `rows` × `cols` values of T starting at `data`, `row_stride_bytes` apart
/// (a field of an array of structs), contiguous within a row; `owner` is kept alive by the view.
/// cols == 0: a 1-D array of `rows` values.
template <class T>
py::array_t<T> view(const py::handle& owner, const T* data, std::size_t rows, std::size_t cols,
                    std::size_t row_stride_bytes) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(row_stride_bytes)};
  if (cols > 0) {
    shape.push_back(static_cast<py::ssize_t>(cols));
    strides.push_back(static_cast<py::ssize_t>(sizeof(T)));
  }
  py::array_t<T> a(shape, strides, data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

/// Doubles from anything array-like, as a C-contiguous float64 array (copied only if needed).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// A 3-vector from a sequence of three numbers; `what` names it in the error.
inline Vec3 to_vec3(const DoubleArray& a, const char* what) {
  if (a.ndim() != 1 || a.shape(0) != 3) {
    throw Error(what, "expected 3 numbers");
  }
  return {a.at(0), a.at(1), a.at(2)};
}

/// A 3-vector as a new float64 array.
inline py::array_t<double> from_vec3(const Vec3& v) {
  py::array_t<double> a(3);
  auto m = a.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < 3; ++i) {
    m(i) = v[i];
  }
  return a;
}

/// A pose as a new 4×4 float64 array (homogeneous transform).
inline py::array_t<double> from_iso3(const Iso3& X) {
  py::array_t<double> a({4, 4});
  auto m = a.mutable_unchecked<2>();
  const Eigen::Matrix4d M = X.matrix();
  for (py::ssize_t r = 0; r < 4; ++r) {
    for (py::ssize_t c = 0; c < 4; ++c) {
      m(r, c) = M(r, c);
    }
  }
  return a;
}

/// A 4×4 homogeneous transform (its rotation re-orthonormalised) from Python; `what` names it.
Iso3 to_iso3(const DoubleArray& a, const char* what);

}  // namespace hapsim::python
