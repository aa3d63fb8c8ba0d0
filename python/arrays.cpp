#include "arrays.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>

namespace extwrench::python {

namespace {

std::string number_text(double v) {
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

// The dtype kinds numpy converts to float64 without losing meaning: signed and unsigned
// integers and floats. Bools ('b') and complex numbers ('c') are refused: a cast would hide a bug.
bool is_real_kind(char kind) { return kind == 'f' || kind == 'i' || kind == 'u'; }

}  // namespace

std::string shape_text(py::ssize_t rows, py::ssize_t cols) {
  if (cols < 0) return "(" + std::to_string(rows) + ",)";
  return "(" + std::to_string(rows) + ", " + std::to_string(cols) + ")";
}

RealArray real_array(const py::handle& obj, const char* name, int ndim) {
  if (obj.is_none()) throw py::type_error(std::string(name) + ": expected an array, got None");
  py::array arr;
  if (py::isinstance<py::array>(obj)) {
    arr = py::reinterpret_borrow<py::array>(obj);
  } else {
    try {
      arr = py::array::ensure(obj);
    } catch (const py::error_already_set&) {
      arr = py::array();
    }
    if (!arr) {
      PyErr_Clear();
      throw py::type_error(std::string(name) + ": expected an array of numbers, got " +
                           std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
    }
  }
  if (!py::array_t<double>::check_(arr)) {
    const py::dtype dt = arr.dtype();
    if (!is_real_kind(dt.kind())) {
      throw py::type_error(std::string(name) + ": expected real numbers (float64), got dtype " +
                           dt.attr("name").cast<std::string>());
    }
    arr = py::array_t<double, py::array::forcecast>::ensure(arr);
    if (!arr) throw py::error_already_set();
  }
  if (arr.ndim() != ndim) {
    throw py::value_error(std::string(name) + ": expected a " + std::to_string(ndim) +
                          "-D array, got " + std::to_string(arr.ndim()) + "-D");
  }
  // A field of a packed structured array (itemsize 12: an f8 beside an i4) has byte strides
  // that are no multiple of 8, and its data may be unaligned: strides in elements cannot say
  // that, so such an array is read through an aligned C-order copy.
  constexpr auto kSize = static_cast<py::ssize_t>(sizeof(double));
  bool elementwise = reinterpret_cast<std::uintptr_t>(arr.data()) % alignof(double) == 0;
  for (py::ssize_t d = 0; d < arr.ndim(); ++d)
    elementwise = elementwise && arr.strides(d) % kSize == 0;
  if (!elementwise) {
    arr = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(arr);
    if (!arr) throw py::error_already_set();
  }
  RealArray out;
  out.data = static_cast<const double*>(arr.data());
  out.rows = arr.shape(0);
  out.row_stride = arr.strides(0) / static_cast<py::ssize_t>(sizeof(double));
  if (ndim == 2) {
    out.cols = arr.shape(1);
    out.col_stride = arr.strides(1) / static_cast<py::ssize_t>(sizeof(double));
  }
  out.owner = std::move(arr);
  return out;
}

void check_shape(const RealArray& a, const char* name, py::ssize_t rows, py::ssize_t cols) {
  const bool two_d = a.owner && py::reinterpret_borrow<py::array>(a.owner).ndim() == 2;
  const bool rows_ok = rows < 0 || a.rows == rows;
  const bool cols_ok = cols < 0 || a.cols == cols;
  if (rows_ok && cols_ok) return;
  std::string want = two_d ? "(" + (rows < 0 ? std::string("N") : std::to_string(rows)) + ", " +
                                 (cols < 0 ? std::string("M") : std::to_string(cols)) + ")"
                           : shape_text(rows);
  throw py::value_error(std::string(name) + ": expected shape " + want + ", got " +
                        shape_text(a.rows, two_d ? a.cols : -1));
}

void check_finite(const RealArray& a, const char* name) {
  const bool two_d = py::reinterpret_borrow<py::array>(a.owner).ndim() == 2;
  for (py::ssize_t i = 0; i < a.rows; ++i) {
    for (py::ssize_t j = 0; j < a.cols; ++j) {
      const double v = a.at(i, j);
      if (std::isfinite(v)) continue;
      const std::string index =
          two_d ? std::to_string(i) + ", " + std::to_string(j) : std::to_string(i);
      throw py::value_error(std::string(name) + "[" + index + "] is " + number_text(v));
    }
  }
}

void read_vector(const py::handle& obj, const char* name, Eigen::Index n, VectorX& out) {
  // Fast path, the one the real-time-like loops take: a float64 array of the right size.
  if (py::array_t<double>::check_(obj)) {
    const auto arr = py::reinterpret_borrow<py::array>(obj);
    if (arr.ndim() == 1 && arr.shape(0) == n) {
      const auto* p = static_cast<const char*>(arr.data());
      const py::ssize_t stride = arr.strides(0);
      if (out.size() != n) out.resize(n);
      for (Eigen::Index i = 0; i < n; ++i) {
        double v;  // memcpy: a field of a packed structured array may be unaligned
        std::memcpy(&v, p + i * stride, sizeof v);
        if (!std::isfinite(v)) {
          throw py::value_error(std::string(name) + "[" + std::to_string(i) + "] is " +
                                number_text(v));
        }
        out[i] = v;
      }
      return;
    }
  }
  const RealArray a = real_array(obj, name, 1);
  check_shape(a, name, n);
  check_finite(a, name);
  if (out.size() != n) out.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) out[i] = a.at(i);
}

Vector3 read_vector3(const py::handle& obj, const char* name) {
  VectorX v;
  read_vector(obj, name, 3, v);
  return v;
}

py::array_t<double> pose_matrix(const Pose& X) {
  py::array_t<double> out({4, 4});
  auto a = out.mutable_unchecked<2>();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) a(i, j) = 0.0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a(i, j) = X.rotation(i, j);
    a(i, 3) = X.translation[i];
  }
  a(3, 3) = 1.0;
  return out;
}

Pose read_pose(const py::handle& obj, const char* name) {
  const RealArray a = real_array(obj, name, 2);
  check_shape(a, name, 4, 4);
  check_finite(a, name);
  if (a.at(3, 0) != 0.0 || a.at(3, 1) != 0.0 || a.at(3, 2) != 0.0 || a.at(3, 3) != 1.0) {
    throw py::value_error(std::string(name) +
                          ": the bottom row of a homogeneous transform must be [0, 0, 0, 1]");
  }
  Pose X;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) X.rotation(i, j) = a.at(i, j);
    X.translation[i] = a.at(i, 3);
  }
  const double orthonormality = (X.rotation.transpose() * X.rotation - Matrix3::Identity()).norm();
  if (!(orthonormality < 1e-6) || !(X.rotation.determinant() > 0.0)) {
    throw py::value_error(std::string(name) +
                          ": the upper-left 3 x 3 block is not a rotation matrix");
  }
  return X;
}

}  // namespace extwrench::python
