// Reading numpy arrays (or anything numpy.asarray accepts) into Eigen vectors with the checks
// every binding shares: dtype, shape, finiteness; the errors name the argument (docs/python.md).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "extwrench/core/types.hpp"

namespace extwrench::python {

namespace py = pybind11;

/// A read-only view of a real 1-D or 2-D array as float64 with its strides in elements; `owner`
/// keeps alive either the caller's array (float64 input: no copy, any layout) or a converted copy.
struct RealArray {
  py::object owner;
  const double* data = nullptr;
  py::ssize_t rows = 0, cols = 1;
  py::ssize_t row_stride = 0, col_stride = 0;  ///< in elements (may be negative or zero)

  [[nodiscard]] double at(py::ssize_t i, py::ssize_t j = 0) const {
    return data[i * row_stride + j * col_stride];
  }
};

/// `obj` as a real array of `ndim` dimensions. TypeError for a dtype that is not a real number
/// (bool, complex, object, strings) or an object numpy cannot read; ValueError for another ndim.
[[nodiscard]] RealArray real_array(const py::handle& obj, const char* name, int ndim);

/// Checks that `a` is (rows,) or (rows, cols) (−1: any); ValueError naming `name` otherwise.
void check_shape(const RealArray& a, const char* name, py::ssize_t rows, py::ssize_t cols = -1);

/// ValueError naming the first NaN/Inf entry ("q[2] is nan", "q[12, 3] is inf").
void check_finite(const RealArray& a, const char* name);

/// A finite vector of exactly n entries into `out` (resized only when its size differs).
void read_vector(const py::handle& obj, const char* name, Eigen::Index n, VectorX& out);
[[nodiscard]] Vector3 read_vector3(const py::handle& obj, const char* name);
/// A 4 × 4 homogeneous transform (finite, rotation block orthonormal to 1e-6) as a Pose.
[[nodiscard]] Pose read_pose(const py::handle& obj, const char* name);
/// X as a (4, 4) homogeneous transform (read_pose's inverse).
[[nodiscard]] py::array_t<double> pose_matrix(const Pose& X);

/// "(5,)" / "(5, 3)": the shape of an array in numpy's spelling.
[[nodiscard]] std::string shape_text(py::ssize_t rows, py::ssize_t cols = -1);

}  // namespace extwrench::python

namespace extwrench::python {

/// A copy into a new numpy array, C order, (rows,) for a column vector else (rows, cols): one
/// allocation, no capsule.
template <typename Derived>
[[nodiscard]] py::array_t<double> to_numpy(const Eigen::MatrixBase<Derived>& m) {
  if constexpr (Derived::ColsAtCompileTime == 1) {
    py::array_t<double> out(m.rows());
    Eigen::Map<VectorX>(out.mutable_data(), m.rows()) = m;
    return out;
  } else {
    py::array_t<double> out({m.rows(), m.cols()});
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        out.mutable_data(), m.rows(), m.cols()) = m;
    return out;
  }
}

}  // namespace extwrench::python
