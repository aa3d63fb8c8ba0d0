// The Python ContactEstimator: the configuration it was made from (so that the batch estimate
// can start a fresh estimator exactly as `extwrench estimate` does) and the live estimator.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "extwrench/io/estimator_config.hpp"

namespace extwrench::python {

namespace py = pybind11;

struct Estimator {
  EstimatorConfig config;
  ContactEstimator estimator;
  std::shared_ptr<const std::vector<std::string>> body_names;
  VectorX q, dq, tau;  ///< argument buffers, sized once

  explicit Estimator(EstimatorConfig c);
  [[nodiscard]] int nq() const { return config.robot.model.nq(); }
};

/// One estimate as Python sees it: the C++ ContactEstimate and the body names of its link.
struct Estimate {
  ContactEstimate value;
  std::shared_ptr<const std::vector<std::string>> body_names;
};

/// The base reading [f; n] (6,) from None, a (3,) force or a (6,) wrench, for `type`.
[[nodiscard]] Vector6 read_reading(const py::handle& obj, SensorType type);

/// The batch estimate of bind_batch.cpp: the rows of estimates.csv as numpy arrays.
[[nodiscard]] py::dict estimate_batch(const Estimator& source, const py::handle& t,
                                      const py::handle& q, const py::handle& dq,
                                      const py::handle& tau, const py::handle& reading);

/// Python's status text of a Status: "ok", or the outcome as in estimates.csv ("non_finite:q[2]";
/// the CSV's column shows the flags where the status is ok).
[[nodiscard]] std::string status_text(Status s);

void bind_batch(py::module_& m);

}  // namespace extwrench::python
