// The Python `Robot`: a loaded robot description (constant Model and geometry) with the Data
// workspace the dynamics functions reuse between calls, and how it was loaded (so that an
// estimator configured from a dict can load the same file the same way).
#pragma once

#include <pybind11/pybind11.h>

#include <filesystem>
#include <memory>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/io/robot_loader.hpp"

namespace extwrench::python {

namespace py = pybind11;

struct Robot {
  RobotDescription description;
  LoadOptions options;
  /// The file it was loaded from, made absolute when it was loaded: an estimator configured
  /// from this Robot later loads that file, whatever the working directory is by then.
  std::filesystem::path absolute_source;
  std::unique_ptr<Data> data;  ///< the workspace of the dynamics functions (the GIL guards it)
  VectorX q, dq, ddq, tau;     ///< argument buffers, sized once

  Robot(RobotDescription d, LoadOptions o);
  [[nodiscard]] const Model& model() const { return description.model; }
  [[nodiscard]] int nq() const { return description.model.nq(); }
  /// A body given by index (negative from the end is refused) or by body/frame name.
  [[nodiscard]] int body(const py::handle& body_or_name, const char* argument) const;
};

void bind_model(py::module_& m);
void bind_dynamics(py::module_& m);
void bind_estimation(py::module_& m);
void bind_io(py::module_& m);
void bind_app(py::module_& m);
void bind_bench(py::module_& m);

}  // namespace extwrench::python
