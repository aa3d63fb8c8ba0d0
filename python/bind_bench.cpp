// C++ timing entries for benchmarks/python_bench.py: the same operations as the bindings, timed
// in C++ in the same process and build, so the Python overhead is a difference of two
// measurements on one machine (Google Benchmark cannot time Python calls).
#include <pybind11/stl.h>

#include <chrono>

#include "arrays.hpp"
#include "estimator.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "robot.hpp"

namespace extwrench::python {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The C++ loop the batch estimate is measured against: the rows already in memory as Samples
/// (as the CLI's reader thread hands them over, CSV excluded), one reset, then update per row.
/// Returns the seconds of the loop.
double time_update_loop(const Estimator& source, const py::handle& t, const py::handle& q,
                        const py::handle& dq, const py::handle& tau, const py::handle& reading) {
  const int n = source.nq();
  const RealArray T = real_array(t, "t", 1), Q = real_array(q, "q", 2),
                  DQ = real_array(dq, "dq", 2), TAU = real_array(tau, "tau", 2);
  if (T.rows < 1) throw py::value_error("t: expected at least one sample");
  check_shape(Q, "q", T.rows, n);
  check_shape(DQ, "dq", T.rows, n);
  check_shape(TAU, "tau", T.rows, n);
  std::vector<Sample> rows(static_cast<std::size_t>(T.rows));
  RealArray R;
  if (!reading.is_none()) {
    R = real_array(reading, "reading", 2);
    check_shape(R, "reading", T.rows, 6);
  }
  for (py::ssize_t k = 0; k < T.rows; ++k) {
    Sample& s = rows[static_cast<std::size_t>(k)];
    s.t = T.at(k);
    s.q.resize(n);
    s.dq.resize(n);
    s.tau.resize(n);
    for (int j = 0; j < n; ++j) {
      s.q[j] = Q.at(k, j);
      s.dq[j] = DQ.at(k, j);
      s.tau[j] = TAU.at(k, j);
    }
    if (R.data != nullptr) {
      s.has_force = s.has_moment = true;
      for (py::ssize_t j = 0; j < R.cols; ++j) s.reading_S[j] = R.at(k, j);
    }
  }
  ContactEstimator est = make_estimator(source.config);
  py::gil_scoped_release release;
  const auto start = Clock::now();
  (void)est.reset(rows.front());
  double sink = 0.0;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    (void)est.update(rows[k]);
    sink += est.result().residual[0];
  }
  const double elapsed = seconds_since(start);
  if (sink == 0.123456789) std::fprintf(stderr, "%g\n", sink);  // keeps the loop observable
  return elapsed;
}

/// Seconds per rnea call on the robot's workspace (the same q, dq, ddq each time).
double time_rnea(Robot& r, const py::handle& q, const py::handle& dq, const py::handle& ddq,
                 long calls) {
  read_vector(q, "q", r.nq(), r.q);
  read_vector(dq, "dq", r.nq(), r.dq);
  read_vector(ddq, "ddq", r.nq(), r.ddq);
  double sink = 0.0;
  const auto start = Clock::now();
  for (long i = 0; i < calls; ++i) sink += rnea(r.model(), *r.data, r.q, r.dq, r.ddq)[0];
  const double elapsed = seconds_since(start);
  if (sink == 0.123456789) std::fprintf(stderr, "%g\n", sink);
  return elapsed / static_cast<double>(calls);
}

/// Seconds per ContactEstimator::update in C++ on a fresh copy of `source`'s estimator, the
/// samples t0 + k dt with the same q, dq, tau, reading (a contact-free steady state).
double time_update(const Estimator& source, double t0, double dt, const py::handle& q,
                   const py::handle& dq, const py::handle& tau, const py::handle& reading,
                   long calls) {
  VectorX Q, DQ, TAU;
  read_vector(q, "q", source.nq(), Q);
  read_vector(dq, "dq", source.nq(), DQ);
  read_vector(tau, "tau", source.nq(), TAU);
  const Vector6 reading_S = read_reading(reading, source.config.options.sensor.type);
  ContactEstimator est = make_estimator(source.config);
  (void)est.reset(t0, Q, DQ, TAU);
  const auto start = Clock::now();
  for (long i = 1; i <= calls; ++i) {
    (void)est.update(t0 + static_cast<double>(i) * dt, Q, DQ, TAU, reading_S);
  }
  return seconds_since(start) / static_cast<double>(calls);
}

}  // namespace

void bind_bench(py::module_& m) {
  m.def("_time_update_loop", &time_update_loop, py::arg("estimator"), py::arg("t"), py::arg("q"),
        py::arg("dq"), py::arg("tau"), py::arg("reading") = py::none());
  m.def("_time_rnea", &time_rnea, py::arg("robot"), py::arg("q"), py::arg("dq"), py::arg("ddq"),
        py::arg("calls"));
  m.def("_time_update", &time_update, py::arg("estimator"), py::arg("t0"), py::arg("dt"),
        py::arg("q"), py::arg("dq"), py::arg("tau"), py::arg("reading"), py::arg("calls"));
}

}  // namespace extwrench::python
