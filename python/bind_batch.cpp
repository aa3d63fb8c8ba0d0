// The batch estimate: a whole log through a fresh estimator in C++ with the GIL released, with
// the row semantics of `extwrench estimate` (src/app/replay.cpp's RowEstimator): the first row
// resets the estimator and is reported "free" with a zero residual.
#include <pybind11/stl.h>

#include <unordered_map>

#include "arrays.hpp"
#include "estimator.hpp"
#include "extwrench/app/contact_tally.hpp"
#include "extwrench/app/joint_range.hpp"

namespace extwrench::python {
namespace {

struct BatchInput {
  RealArray t, q, dq, tau, reading;
  bool has_dq = false, has_reading = false;
};

BatchInput read_batch(const Estimator& e, const py::handle& t, const py::handle& q,
                      const py::handle& dq, const py::handle& tau, const py::handle& reading) {
  BatchInput in;
  const int n = e.nq();
  in.t = real_array(t, "t", 1);
  const py::ssize_t rows = in.t.rows;
  if (rows < 1) throw py::value_error("t: expected at least one sample");
  in.q = real_array(q, "q", 2);
  check_shape(in.q, "q", rows, n);
  in.has_dq = !dq.is_none();
  if (in.has_dq) {
    in.dq = real_array(dq, "dq", 2);
    check_shape(in.dq, "dq", rows, n);
  }
  in.tau = real_array(tau, "tau", 2);
  check_shape(in.tau, "tau", rows, n);
  const SensorType type = e.config.options.sensor.type;
  in.has_reading = !reading.is_none();
  if (in.has_reading) {
    in.reading = real_array(reading, "reading", 2);
    if (!(in.reading.cols == 6 || (in.reading.cols == 3 && type != SensorType::kForceTorque))) {
      check_shape(in.reading, "reading", rows, 6);
    }
    check_shape(in.reading, "reading", rows, in.reading.cols);
  } else if (type != SensorType::kNone) {
    throw py::value_error(std::string("reading: the configured sensor (") +
                          std::string(to_string(type)) +
                          ") needs the base readings, shape (N, 6) or (N, 3)");
  }
  check_finite(in.t, "t");
  check_finite(in.q, "q");
  if (in.has_dq) check_finite(in.dq, "dq");
  check_finite(in.tau, "tau");
  if (in.has_reading) check_finite(in.reading, "reading");
  for (py::ssize_t k = 1; k < rows; ++k) {
    if (!(in.t.at(k) > in.t.at(k - 1))) {
      throw py::value_error("t[" + std::to_string(k) + "]: the time stamps must increase (t[" +
                            std::to_string(k) + "] = " + std::to_string(in.t.at(k)) + " <= t[" +
                            std::to_string(k - 1) + "] = " + std::to_string(in.t.at(k - 1)) + ")");
    }
  }
  return in;
}

/// The output columns, allocated with the GIL held and written without it.
struct BatchOutput {
  py::array_t<double> t, force, moment, point, point_L, line_point, line_direction, surface, cond,
      residual, threshold, sigma_f, sigma_m, sigma_line, sigma_point;
  py::array_t<bool> contact;
  py::array_t<std::int32_t> link, status;
  py::array_t<std::uint32_t> flags;
  py::array_t<std::uint64_t> link_candidates;
  std::vector<std::string> status_names;

  BatchOutput(py::ssize_t rows, int n)
      : t(rows),
        force({rows, py::ssize_t{3}}),
        moment({rows, py::ssize_t{3}}),
        point({rows, py::ssize_t{3}}),
        point_L({rows, py::ssize_t{3}}),
        line_point({rows, py::ssize_t{3}}),
        line_direction({rows, py::ssize_t{3}}),
        surface(rows),
        cond(rows),
        residual({rows, static_cast<py::ssize_t>(n)}),
        threshold({rows, static_cast<py::ssize_t>(n)}),
        sigma_f(rows),
        sigma_m(rows),
        sigma_line(rows),
        sigma_point(rows),
        contact(rows),
        link(rows),
        status(rows),
        flags(rows),
        link_candidates(rows) {}
};

struct RowWriter {
  double *t, *force, *moment, *point, *point_L, *line_point, *line_direction, *surface, *cond,
      *residual, *threshold, *sigma_f, *sigma_m, *sigma_line, *sigma_point;
  bool* contact;
  std::int32_t *link, *status;
  std::uint32_t* flags;
  std::uint64_t* link_candidates;
  int n;
  int bodies;
  std::vector<std::string>* status_names;
  std::unordered_map<std::string, int> status_index;
  std::uint32_t cached_flags = 0;
  int cached_index = -1;

  explicit RowWriter(BatchOutput& o, int n_, int bodies_)
      : t(o.t.mutable_data()),
        force(o.force.mutable_data()),
        moment(o.moment.mutable_data()),
        point(o.point.mutable_data()),
        point_L(o.point_L.mutable_data()),
        line_point(o.line_point.mutable_data()),
        line_direction(o.line_direction.mutable_data()),
        surface(o.surface.mutable_data()),
        cond(o.cond.mutable_data()),
        residual(o.residual.mutable_data()),
        threshold(o.threshold.mutable_data()),
        sigma_f(o.sigma_f.mutable_data()),
        sigma_m(o.sigma_m.mutable_data()),
        sigma_line(o.sigma_line.mutable_data()),
        sigma_point(o.sigma_point.mutable_data()),
        contact(o.contact.mutable_data()),
        link(o.link.mutable_data()),
        status(o.status.mutable_data()),
        flags(o.flags.mutable_data()),
        link_candidates(o.link_candidates.mutable_data()),
        n(n_),
        bodies(bodies_),
        status_names(&o.status_names) {}

  int status_of(const ContactEstimate& e) {
    if (e.status.ok() && e.flags == cached_flags && cached_index >= 0) return cached_index;
    const std::string text = status_text_of(e);
    auto [it, added] = status_index.emplace(text, static_cast<int>(status_names->size()));
    if (added) status_names->push_back(text);
    if (e.status.ok()) {
      cached_flags = e.flags;
      cached_index = it->second;
    }
    return it->second;
  }

  static std::string status_text_of(const ContactEstimate& e) {
    return e.status.ok() ? describe_flags(e.flags) : status_text(e.status);
  }

  static void put3(double* dst, std::size_t k, const Vector3& v) {
    for (int i = 0; i < 3; ++i) dst[3 * k + static_cast<std::size_t>(i)] = v[i];
  }

  /// Row k: the estimate and the detector's thresholds τ_thr it was compared with.
  void write(std::size_t k, const ContactEstimate& e, const VectorX& thresholds) {
    t[k] = e.t;
    contact[k] = e.contact;
    // As estimates.csv: the link column is empty unless a contact is declared.
    link[k] = e.contact && e.link >= 0 && e.link < bodies ? e.link : -1;
    put3(force, k, e.force_W);
    put3(moment, k, e.moment_W);
    put3(point, k, e.point_W);
    put3(point_L, k, e.point_L);
    put3(line_point, k, e.line_point_W);
    put3(line_direction, k, e.line_direction_W);
    surface[k] = e.surface_distance;
    cond[k] = e.condition_number;
    flags[k] = e.flags;
    link_candidates[k] = e.link_candidates;
    sigma_f[k] = e.sigma_force;
    sigma_m[k] = e.sigma_moment;
    sigma_line[k] = e.sigma_line;
    sigma_point[k] = e.sigma_point;
    status[k] = status_of(e);
    double* r = residual + k * static_cast<std::size_t>(n);
    for (int i = 0; i < n; ++i) r[i] = e.residual.size() == n ? e.residual[i] : std::nan("");
    double* thr = threshold + k * static_cast<std::size_t>(n);
    for (int i = 0; i < n; ++i) thr[i] = thresholds.size() == n ? thresholds[i] : std::nan("");
  }
};

void run_rows(ContactEstimator& est, const BatchInput& in, int n, RowWriter& w) {
  VectorX q(n), dq(n), tau(n), q_prev(n);
  Vector6 reading = Vector6::Zero();
  ContactEstimate first;
  bool started = false;
  const auto rows = in.t.rows;
  for (py::ssize_t k = 0; k < rows; ++k) {
    const double t = in.t.at(k);
    for (int j = 0; j < n; ++j) {
      q[j] = in.q.at(k, j);
      tau[j] = in.tau.at(k, j);
    }
    if (in.has_dq) {
      for (int j = 0; j < n; ++j) dq[j] = in.dq.at(k, j);
    } else if (k == 0) {
      // As LogReader without dq columns: forward difference on the first row, then backward.
      for (int j = 0; j < n; ++j)
        dq[j] = rows > 1 ? (in.q.at(1, j) - q[j]) / (in.t.at(1) - t) : 0.0;
    } else {
      for (int j = 0; j < n; ++j) dq[j] = (q[j] - q_prev[j]) / (t - in.t.at(k - 1));
    }
    q_prev = q;
    if (in.has_reading) {
      for (py::ssize_t j = 0; j < in.reading.cols; ++j) reading[j] = in.reading.at(k, j);
    }
    if (started) {
      (void)est.update(t, q, dq, tau, reading);  // the status is in the status column
      w.write(static_cast<std::size_t>(k), est.result(), est.detector().thresholds());
      continue;
    }
    const Status st = est.reset(t, q, dq, tau);
    first = ContactEstimate{};
    first.t = t;
    first.residual = VectorX::Zero(n);
    first.status = st;
    started = st.ok();
    w.write(static_cast<std::size_t>(k), first, est.detector().thresholds());
  }
}

}  // namespace

py::dict estimate_batch(const Estimator& source, const py::handle& t, const py::handle& q,
                        const py::handle& dq, const py::handle& tau, const py::handle& reading) {
  const BatchInput in = read_batch(source, t, q, dq, tau, reading);
  const int n = source.nq();
  // A fresh estimator from the configuration: what `extwrench estimate` builds.
  ContactEstimator est = make_estimator(source.config);
  BatchOutput out(in.t.rows, n);
  RowWriter writer(out, n, source.config.robot.model.num_bodies());
  {
    py::gil_scoped_release release;
    run_rows(est, in, n, writer);
  }
  py::dict d;
  d["t"] = out.t;
  d["contact"] = out.contact;
  d["link"] = out.link;
  d["force_W"] = out.force;
  d["moment_W"] = out.moment;
  d["point_W"] = out.point;
  d["line_point_W"] = out.line_point;
  d["status_index"] = out.status;
  d["status_names"] = out.status_names;
  d["cond"] = out.cond;
  d["residual"] = out.residual;
  d["threshold"] = out.threshold;
  d["point_L"] = out.point_L;
  d["line_direction_W"] = out.line_direction;
  d["surface_distance"] = out.surface;
  d["flags"] = out.flags;
  d["link_candidates"] = out.link_candidates;
  d["sigma_f"] = out.sigma_f;
  d["sigma_m"] = out.sigma_m;
  d["sigma_line"] = out.sigma_line;
  d["sigma_point"] = out.sigma_point;
  return d;
}

/// `a` as a 1-D array of `rows` entries of type T (numpy converts what it can: a TypeError
/// otherwise); ValueError naming `name` for another shape.
template <typename T>
py::array_t<T, py::array::forcecast> column_of(const py::handle& a, const char* name,
                                               py::ssize_t rows) {
  py::array_t<T, py::array::forcecast> column(py::reinterpret_borrow<py::object>(a));
  if (column.ndim() != 1 || column.shape(0) != rows) {
    throw py::value_error(std::string(name) + ": expected shape " + shape_text(rows) + ", got " +
                          (column.ndim() == 1 ? shape_text(column.shape(0))
                                              : std::to_string(column.ndim()) + " dimensions"));
  }
  return column;
}

/// The tally of `extwrench estimate`'s contact line and notes (app/contact_tally.hpp) over the
/// columns of estimate()'s dict.
py::dict contact_summary_py(const Estimator& source, const py::handle& t, const py::handle& contact,
                            const py::handle& link, const py::handle& flags) {
  const RealArray time = real_array(t, "t", 1);
  check_finite(time, "t");
  const py::ssize_t rows = time.rows;
  const auto on = column_of<bool>(contact, "contact", rows);
  const auto body = column_of<std::int32_t>(link, "link", rows);
  const bool has_flags = !flags.is_none();
  py::array_t<std::uint32_t, py::array::forcecast> bits;
  if (has_flags) bits = column_of<std::uint32_t>(flags, "flags", rows);
  const Model& model = source.config.robot.model;
  ContactTally tally(model.num_bodies());
  const auto disagreement = static_cast<std::uint32_t>(EstimateFlag::kDisagreement);
  for (py::ssize_t k = 0; k < rows; ++k) {
    tally.add(time.at(k), on.at(k), body.at(k), has_flags && (bits.at(k) & disagreement) != 0);
  }
  py::dict by_link;
  for (std::size_t l = 0; l < tally.samples_by_link.size(); ++l) {
    if (tally.samples_by_link[l] > 0)
      by_link[py::str(model.bodies[l].name)] = tally.samples_by_link[l];
  }
  py::dict d;
  d["samples"] = tally.rows;
  d["contact_samples"] = tally.contact_samples;
  d["episodes"] = tally.contact_episodes;
  d["disagreement_samples"] = tally.disagreement_samples;
  d["by_link"] = by_link;
  d["duration"] = tally.duration();
  d["text"] = contact_summary(tally, model);
  d["note"] = frequent_alarms_note(tally);
  d["disagreement_warning"] = disagreement_warning(tally);
  d["time_step_note"] = time_step_note(tally);
  d["base_contact_warning"] = base_contact_warning(tally, model);
  d["time_gap_note"] = time_gap_note(tally);
  return d;
}

/// The note of `extwrench estimate` on positions far outside the limits (degrees, a glitch), for
/// estimate()'s arrays: "" when there is none.
std::string joint_range_note(const Estimator& source, const py::handle& t, const py::handle& q) {
  const RealArray time = real_array(t, "t", 1);
  const RealArray q_rows = real_array(q, "q", 2);
  check_shape(q_rows, "q", time.rows, source.nq());
  JointRangeCheck check(source.config.robot.model);
  VectorX row(source.nq());
  for (py::ssize_t k = 0; k < time.rows; ++k) {
    for (Eigen::Index i = 0; i < row.size(); ++i) row[i] = q_rows.at(k, i);
    check.add(time.at(k), row);
  }
  return check.note();
}

void bind_batch(py::module_& m) {
  m.def("_estimate", &estimate_batch, py::arg("estimator"), py::arg("t"), py::arg("q"),
        py::arg("dq"), py::arg("tau"), py::arg("reading") = py::none());
  m.def("_contact_summary", &contact_summary_py, py::arg("estimator"), py::arg("t"),
        py::arg("contact"), py::arg("link"), py::arg("flags") = py::none());
  m.def("_joint_range_note", &joint_range_note, py::arg("estimator"), py::arg("t"), py::arg("q"));
}

}  // namespace extwrench::python
