// Robot logs in and estimates out as numpy arrays (docs/log_format.md), and the metrics of
// estimates against the truth (the MetricsAccumulator of metrics.json).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <charconv>
#include <string_view>

#include "arrays.hpp"
#include "estimator.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/sim/metrics.hpp"
#include "robot.hpp"

namespace extwrench::python {
namespace {

const Model& model_of(const py::handle& robot) {
  if (py::isinstance<Robot>(robot)) return robot.cast<const Robot&>().model();
  if (py::isinstance<Estimator>(robot)) return robot.cast<const Estimator&>().config.robot.model;
  throw py::type_error("robot: expected an extwrench.Robot or extwrench.ContactEstimator");
}

/// Rows of a fixed width, grown row by row, then one numpy array (rows, width).
struct Column {
  int width;
  std::vector<double> values;
  explicit Column(int w) : width(w) {}
  void add(const double* v) { values.insert(values.end(), v, v + width); }
  [[nodiscard]] py::array_t<double> array() const {
    const auto rows = static_cast<py::ssize_t>(values.size() / static_cast<std::size_t>(width));
    py::array_t<double> out({rows, static_cast<py::ssize_t>(width)});
    std::copy(values.begin(), values.end(), out.mutable_data());
    return out;
  }
};

py::dict read_log_py(const std::filesystem::path& path, const py::handle& robot) {
  const Model& model = model_of(robot);
  LogReader reader(path, model);
  const LogLayout layout = reader.layout();
  const int n = model.nq();
  std::vector<double> t;
  Column q(n), dq(n), tau(n), reading(6), force(3), moment(3), point(3), tau_ext(n);
  std::vector<std::int32_t> body, contacts;
  std::vector<std::string> links;
  Sample s;
  while (reader.next(s)) {
    t.push_back(s.t);
    q.add(s.q.data());
    dq.add(s.dq.data());
    tau.add(s.tau.data());
    if (layout.force) reading.add(s.reading_S.data());
    if (layout.truth) {
      force.add(s.truth.force_W.data());
      moment.add(s.truth.moment_W.data());
      point.add(s.truth.point_W.data());
      body.push_back(s.truth.body);
      contacts.push_back(s.truth.contacts);
      links.push_back(s.truth.link);
    }
    if (layout.true_tau_ext) tau_ext.add(s.truth.tau_ext.data());
  }
  if (t.empty()) throw py::value_error(path.string() + ": the log has a header but no rows");
  py::dict d;
  d["t"] = py::array_t<double>(static_cast<py::ssize_t>(t.size()), t.data());
  d["q"] = q.array();
  d["dq"] = dq.array();
  d["tau"] = tau.array();
  d["dq_logged"] = layout.velocity;
  if (layout.force) d["reading"] = reading.array();
  d["has_moment"] = layout.moment;
  if (layout.truth) {
    d["true_link"] = py::array(py::cast(links));
    d["true_body"] = py::array_t<std::int32_t>(static_cast<py::ssize_t>(body.size()), body.data());
    d["true_contacts"] =
        py::array_t<std::int32_t>(static_cast<py::ssize_t>(contacts.size()), contacts.data());
    d["true_force_W"] = force.array();
    d["true_moment_W"] = moment.array();
    d["true_point_W"] = point.array();
  }
  if (layout.true_tau_ext) d["true_tau_ext"] = tau_ext.array();
  d["ignored_columns"] = reader.ignored_columns();
  return d;
}

/// A key of a dict of arrays, checked for its shape (rows, cols) (cols −1: 1-D).
RealArray column(const py::dict& d, const char* dict_name, const char* key, py::ssize_t rows,
                 py::ssize_t cols) {
  if (!d.contains(key)) {
    throw py::key_error(std::string(dict_name) + ": missing key '" + key + "'");
  }
  const std::string name = std::string(dict_name) + "['" + key + "']";
  py::object value = d[key];
  // The boolean columns (contact) are read as 0 / 1.
  if (py::isinstance<py::array>(value) &&
      py::reinterpret_borrow<py::array>(value).dtype().kind() == 'b') {
    value = value.attr("astype")("float64");
  }
  RealArray a = real_array(value, name.c_str(), cols < 0 ? 1 : 2);
  check_shape(a, name.c_str(), rows, cols);
  return a;
}

Vector3 row3(const RealArray& a, py::ssize_t k) { return {a.at(k, 0), a.at(k, 1), a.at(k, 2)}; }

/// The Status of a status text of estimates.csv ("non_finite:q[2]"); ok for a flags text.
/// ValueError naming row `row` for a code, channel or index this version does not write.
Status parse_status(const std::string& text, py::ssize_t row) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) return {};
  const auto bad = [&](const std::string& what) {
    return py::value_error("estimates['status'][" + std::to_string(row) + "]: '" + text +
                           "': " + what +
                           " (estimates.csv writes CODE:CHANNEL or CODE:CHANNEL[INDEX], "
                           "docs/log_format.md)");
  };
  Status s;
  bool code_known = false;
  for (int c = 1; c <= static_cast<int>(StatusCode::kSingular); ++c) {
    if (to_string(static_cast<StatusCode>(c)) == text.substr(0, colon)) {
      s.code = static_cast<StatusCode>(c);
      code_known = true;
    }
  }
  if (!code_known) throw bad("unknown code '" + text.substr(0, colon) + "'");
  const auto bracket = text.find('[', colon);
  const std::string channel = text.substr(
      colon + 1, bracket == std::string::npos ? std::string::npos : bracket - colon - 1);
  bool channel_known = false;
  for (int c = 0; c <= static_cast<int>(Channel::kBaseWrench); ++c) {
    if (to_string(static_cast<Channel>(c)) == channel) {
      s.channel = static_cast<Channel>(c);
      channel_known = true;
    }
  }
  if (!channel_known) throw bad("unknown channel '" + channel + "'");
  if (bracket != std::string::npos) {
    const std::string index = text.substr(bracket + 1);
    int value = -1;
    const auto [end, ec] = std::from_chars(index.data(), index.data() + index.size(), value);
    if (ec != std::errc() || value < 0 || std::string_view(end) != "]")
      throw bad("the index is not a count in brackets");
    s.index = value;
  }
  return s;
}

/// Row k of an estimates dict (the output of extwrench.estimate) as a ContactEstimate.
struct EstimateRows {
  RealArray t, contact, link, force, moment, point, line_point, line_direction, cond, residual,
      flags;
  std::vector<std::string> status;
  /// Bit l: body l (the estimates.csv column link_candidates); absent in older dicts.
  py::array_t<std::uint64_t> link_candidates;
  /// The 1-σ columns (sigma_f, sigma_m, sigma_line, sigma_point); absent in older dicts: NaN.
  RealArray sigma[4];
  bool has_sigma[4] = {false, false, false, false};
  py::ssize_t rows = 0;
  int n = 0;

  EstimateRows(const py::dict& d, int n_) : n(n_) {
    t = column(d, "estimates", "t", -1, -1);
    rows = t.rows;
    contact = column(d, "estimates", "contact", rows, -1);
    link = column(d, "estimates", "link", rows, -1);
    force = column(d, "estimates", "force_W", rows, 3);
    moment = column(d, "estimates", "moment_W", rows, 3);
    point = column(d, "estimates", "point_W", rows, 3);
    line_point = column(d, "estimates", "line_point_W", rows, 3);
    line_direction = column(d, "estimates", "line_direction_W", rows, 3);
    cond = column(d, "estimates", "cond", rows, -1);
    residual = column(d, "estimates", "residual", rows, n);
    flags = column(d, "estimates", "flags", rows, -1);
    if (d.contains("link_candidates")) {
      link_candidates =
          py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(
              d["link_candidates"]);
      if (!link_candidates || link_candidates.ndim() != 1 || link_candidates.shape(0) != rows) {
        throw py::value_error("estimates['link_candidates']: expected " + std::to_string(rows) +
                              " unsigned integers (bit l: body l)");
      }
    }
    const char* sigma_names[4] = {"sigma_f", "sigma_m", "sigma_line", "sigma_point"};
    for (int i = 0; i < 4; ++i) {
      has_sigma[i] = d.contains(sigma_names[i]);
      if (has_sigma[i]) sigma[i] = column(d, "estimates", sigma_names[i], rows, -1);
    }
    if (d.contains("status")) status = d["status"].cast<std::vector<std::string>>();
    if (!status.empty() && static_cast<py::ssize_t>(status.size()) != rows) {
      throw py::value_error("estimates['status']: expected " + std::to_string(rows) + " entries");
    }
  }

  void get(py::ssize_t k, ContactEstimate& e) const {
    e.t = t.at(k);
    e.contact = contact.at(k) != 0.0;
    e.link = static_cast<int>(link.at(k));
    e.force_W = row3(force, k);
    e.moment_W = row3(moment, k);
    e.point_W = row3(point, k);
    e.line_point_W = row3(line_point, k);
    e.line_direction_W = row3(line_direction, k);
    e.condition_number = cond.at(k);
    e.residual.resize(n);
    for (int i = 0; i < n; ++i) e.residual[i] = residual.at(k, i);
    e.flags = static_cast<std::uint32_t>(flags.at(k));
    e.link_candidates = link_candidates ? link_candidates.at(k) : 0;
    const auto sigma_at = [&](int i) { return has_sigma[i] ? sigma[i].at(k) : std::nan(""); };
    e.sigma_force = sigma_at(0);
    e.sigma_moment = sigma_at(1);
    e.sigma_line = sigma_at(2);
    e.sigma_point = sigma_at(3);
    e.status = status.empty() ? Status{} : parse_status(status[static_cast<std::size_t>(k)], k);
  }
};

void write_estimates_py(const std::filesystem::path& path, const py::handle& robot,
                        const py::dict& estimates) {
  const Model& model = model_of(robot);
  const EstimateRows rows(estimates, model.nq());
  EstimatesWriter writer(path, model);
  ContactEstimate e;
  for (py::ssize_t k = 0; k < rows.rows; ++k) {
    rows.get(k, e);
    writer.write(e);
  }
  writer.close();
}

py::dict stat(const sim::ErrorStat& s) {
  py::dict d;
  d["rms"] = s.rms();
  d["max"] = s.count > 0 ? s.max : std::nan("");
  d["samples"] = s.count;
  return d;
}

py::dict metrics_py(const py::dict& truth, const py::dict& estimates, double from, double to,
                    const std::vector<std::pair<double, double>>& exclude) {
  // As `extwrench estimate` checks --metrics-from, --metrics-to and --exclude: NaN would count
  // every sample, and an interval with from >= to would exclude none, both without a word.
  if (std::isnan(from) || std::isnan(to) || !(from < to)) {
    throw py::value_error("start, stop: expected times in seconds with start < stop, got " +
                          std::string(py::str(py::float_(from))) + ", " +
                          std::string(py::str(py::float_(to))));
  }
  for (std::size_t i = 0; i < exclude.size(); ++i) {
    if (!(exclude[i].first < exclude[i].second)) {
      throw py::value_error("exclude[" + std::to_string(i) +
                            "]: expected (from, to) in seconds with from < to, got (" +
                            std::string(py::str(py::float_(exclude[i].first))) + ", " +
                            std::string(py::str(py::float_(exclude[i].second))) + ")");
    }
  }
  const RealArray t = column(truth, "truth", "t", -1, -1);
  const RealArray body = column(truth, "truth", "true_body", t.rows, -1);
  const RealArray contacts = column(truth, "truth", "true_contacts", t.rows, -1);
  const RealArray force = column(truth, "truth", "true_force_W", t.rows, 3);
  const RealArray moment = column(truth, "truth", "true_moment_W", t.rows, 3);
  const RealArray point = column(truth, "truth", "true_point_W", t.rows, 3);
  if (!estimates.contains("residual")) {
    throw py::key_error("estimates: missing key 'residual'");
  }
  const auto n =
      static_cast<int>(real_array(estimates["residual"], "estimates['residual']", 2).cols);
  const EstimateRows rows(estimates, n);
  if (rows.rows != t.rows) throw py::value_error("estimates: not as many rows as the truth");
  sim::MetricsAccumulator acc(sim::MetricsWindow{from, to, exclude});
  Truth tr;
  ContactEstimate e;
  for (py::ssize_t k = 0; k < t.rows; ++k) {
    tr.body = static_cast<int>(body.at(k));
    tr.contacts = static_cast<int>(contacts.at(k));
    tr.force_W = row3(force, k);
    tr.moment_W = row3(moment, k);
    tr.point_W = row3(point, k);
    rows.get(k, e);
    acc.add(t.at(k), tr, e);
  }
  const sim::Metrics m = acc.result();
  py::dict d;
  d["samples"] = m.samples;
  d["contact_samples"] = m.contact_samples;
  d["free_samples"] = m.free_samples;
  d["force_error"] = stat(m.force);
  d["moment_error"] = stat(m.moment);
  d["line_of_action_distance"] = stat(m.line);
  d["surface_point_error"] = stat(m.surface);
  d["force_not_estimated"] = m.force_not_estimated;
  d["line_not_estimated"] = m.line_not_estimated;
  d["isolation_accuracy"] = m.isolation_accuracy();
  d["right_link_samples"] = m.right_link;
  d["missed_detections"] = m.missed;
  d["false_alarms"] = m.false_alarms;
  d["false_alarms_release"] = m.false_alarms_release;
  d["false_alarm_rate"] = m.false_alarm_rate();
  py::dict u;
  u["samples"] = m.sigma_samples;
  u["force_within_2sigma"] = m.force_two_sigma_coverage();
  u["uncertain"] = m.uncertain;
  u["large_force_error_unflagged"] = m.large_force_error_unflagged;
  d["uncertainty"] = u;
  d["onsets"] = m.onsets;
  d["onsets_detected"] = m.onsets_detected;
  d["onsets_already_declared"] = m.onsets_already_declared;
  d["mean_detection_delay"] = m.mean_detection_delay();
  d["max_detection_delay"] = m.delay_max;
  return d;
}

}  // namespace

void bind_io(py::module_& m) {
  m.def("read_log", &read_log_py, py::arg("path"), py::arg("robot"),
        R"(Reads a robot log (CSV, docs/log_format.md) into numpy arrays (N rows).

Keys: t (N,), q, dq, tau (N, n) (dq differentiated when not logged: dq_logged False),
reading (N, 6) [f; n] sensor frame when the log has fs_* columns (moment zero without ms_*);
with truth columns: true_link (N,) names, true_body (N,) body index (-1 free), true_contacts,
true_force_W, true_moment_W, true_point_W (N, 3), world frame; true_tau_ext (N, n) when logged.
robot: a Robot or ContactEstimator (n, and the body names of true_link).)");
  m.def("write_estimates", &write_estimates_py, py::arg("path"), py::arg("robot"),
        py::arg("estimates"),
        "Writes the dict of extwrench.estimate as estimates.csv, byte for byte as `extwrench "
        "estimate` writes it.");
  m.def("metrics", &metrics_py, py::arg("truth"), py::arg("estimates"), py::kw_only(),
        py::arg("start") = 0.0, py::arg("stop") = std::numeric_limits<double>::infinity(),
        py::arg("exclude") = std::vector<std::pair<double, double>>{},
        R"(Accuracy of estimates against the truth of a log (read_log's dict), as metrics.json
(docs/log_format.md): over [start, stop] s minus the excluded (from, to) intervals.)");
}

}  // namespace extwrench::python
