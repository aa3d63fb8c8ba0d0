// Whole jobs: a simulation scenario run as `extwrench simulate` runs it (app/scenario_run.hpp),
// and a calibration from a log as `extwrench calibrate` computes it (app/calibrate_log.hpp).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "estimator.hpp"
#include "extwrench/app/calibrate_log.hpp"
#include "extwrench/app/scenario_run.hpp"
#include "extwrench/core/error.hpp"
#include "robot.hpp"

namespace extwrench::python {
namespace {

py::list run_scenario_py(const std::filesystem::path& scenario_path,
                         const std::filesystem::path& out_dir, bool figures,
                         const std::vector<std::filesystem::path>& package_path) {
  LoadOptions load;
  load.package_path = package_path;
  const Scenario scenario = load_scenario(scenario_path, load);
  RunOptions run;
  run.figures = figures;
  run.progress = false;
  std::vector<SeedResult> results;
  {
    py::gil_scoped_release release;
    results = run_scenario(scenario, out_dir, run);
  }
  py::list out;
  for (const SeedResult& r : results) {
    py::dict d;
    d["seed"] = r.seed;
    d["dir"] = r.dir;
    d["samples"] = r.samples;
    d["peak_condition"] = r.peak_condition;
    d["peak_time"] = r.peak_time;
    std::vector<std::string> schemes;
    for (const auto& s : r.schemes) schemes.push_back(s.name);
    d["schemes"] = schemes;
    d["notes"] = r.notes;
    out.append(d);
  }
  return out;
}

// The calibrate keywords in messages: "smoothing_velocity: not used with sign='dahl'".
std::string keyword_name(std::string_view key) { return std::string(key); }
std::string keyword_value(std::string_view text) { return "'" + std::string(text) + "'"; }
constexpr ArgumentSpelling kKeywordSpelling{keyword_name, keyword_value, "="};

py::dict friction_dict(const JointFriction& f) {
  py::dict d;
  d["sign"] = std::string(to_string(f.sign));
  d["viscous"] = f.viscous;
  d["coulomb"] = f.coulomb;
  d["offset"] = f.offset;
  if (f.sign == SmoothSign::kDahl) {
    d["presliding_displacement"] = f.presliding;
  } else {
    d["smoothing_velocity"] = f.joint_smoothing;
  }
  if (f.velocity_shift.size() > 0) d["velocity_shift"] = f.velocity_shift;
  return d;
}

py::list joints_list(const std::vector<JointFitReport>& joints) {
  py::list out;
  for (const JointFitReport& j : joints) {
    py::dict d;
    d["rms_before"] = j.rms_before;
    d["rms_after"] = j.rms_after;
    d["max_before"] = j.max_before;
    d["max_after"] = j.max_after;
    d["max_after_t"] = j.max_after_t;
    d["variance_explained"] = j.variance_explained;
    d["noise_std"] = j.noise_std;
    d["crossing_rate"] = j.crossing_rate;
    d["condition"] = j.condition;
    d["threshold"] = j.threshold;
    d["threshold_rule"] = j.threshold_from_max ? "largest_residual" : "gaussian";
    d["threshold_form"] = j.speed_dependent ? "speed" : "constant";
    d["threshold_constant"] = j.threshold_constant;
    d["threshold_per_speed"] = j.speed_dependent ? j.threshold_per_speed : 0.0;
    d["noise_at_rest"] = j.noise_at_rest;
    d["noise_per_speed"] = j.noise_per_speed;
    d["inertia_correction"] = j.inertia_correction;
    out.append(d);
  }
  return out;
}

// Per link 1..n (the report's index 0 is unused).
VectorX per_link(const std::vector<double>& v) {
  VectorX out(static_cast<Eigen::Index>(v.empty() ? 0 : v.size() - 1));
  for (Eigen::Index l = 0; l < out.size(); ++l) out[l] = v[static_cast<std::size_t>(l) + 1];
  return out;
}

py::object holdout_dict(const std::optional<HoldoutReport>& h) {
  if (!h) return py::none();
  py::dict d;
  d["samples"] = h->samples;
  d["duration"] = h->duration;
  d["false_alarms"] = h->false_alarms;
  d["raw_alarms"] = h->raw_alarms;
  d["uncalibrated_false_alarms"] = h->uncalibrated_false_alarms;
  d["constant_threshold_false_alarms"] = h->constant_threshold_false_alarms;
  d["best_constant_threshold"] = h->best_constant_threshold;
  d["calibrated_max_residual"] = h->calibrated_max_residual;
  d["lever"] = h->lever;
  d["min_force_calibrated"] = per_link(h->min_force_calibrated);
  d["min_force_calibrated_constant"] = per_link(h->min_force_calibrated_constant);
  d["min_force_best_constant"] = per_link(h->min_force_constant);
  d["min_force_calibrated_quiet"] = per_link(h->min_force_calibrated_quiet);
  if (h->tracking_rms_calibrated.size() > 0) {
    d["tracking_rms_uncalibrated"] = h->tracking_rms_uncalibrated;
    d["tracking_rms_calibrated"] = h->tracking_rms_calibrated;
  }
  return d;
}

py::dict calibrate_py(const Estimator& estimator, const std::filesystem::path& log, double holdout,
                      const std::string& sign, double smoothing_velocity,
                      double presliding_displacement, double false_alarms_per_hour,
                      const std::string& thresholds, bool payload, bool known_torque, bool inertia,
                      bool ignore_extra_joints, const std::optional<std::filesystem::path>& out) {
  CalibrateArguments arguments;
  arguments.holdout = holdout;
  arguments.sign = sign;
  arguments.smoothing_velocity = smoothing_velocity;
  arguments.presliding_displacement = presliding_displacement;
  arguments.false_alarms_per_hour = false_alarms_per_hour;
  arguments.thresholds = thresholds;
  arguments.payload = payload;
  arguments.known_torque = known_torque;
  arguments.inertia = inertia;
  const CalibrationOptions options = calibration_options(arguments, kKeywordSpelling);
  CalibrateLogResult run;
  std::string yaml;
  {
    py::gil_scoped_release release;
    run = calibrate_log(estimator.config, log, options, holdout, ignore_extra_joints);
    yaml = calibration_yaml(run);
  }
  if (out) write_calibration(*out, yaml);
  const Calibration& c = run.calibration;
  py::dict d;
  d["source"] = c.source;
  d["rows"] = run.rows;
  d["fit_rows"] = run.fit_rows;
  d["samples_used"] = c.samples_used;
  d["friction"] = friction_dict(c.friction);
  d["tau_min"] = c.tau_threshold;
  d["tau_per_speed"] = c.tau_per_speed;
  d["residual_noise"] = c.residual_noise;
  d["residual_cutoff"] = c.residual_cutoff;
  d["velocity_cutoff"] = c.velocity_cutoff;
  d["inertia_correction"] = c.inertia_correction;
  d["observer_gain"] = c.observer_gain;
  d["sensor_bias"] = c.sensor_type == SensorType::kNone ? py::object(py::none())
                                                        : py::cast(Vector6(c.sensor_bias_S));
  d["f_min"] =
      c.sensor_type == SensorType::kNone ? py::object(py::none()) : py::cast(c.force_threshold);
  d["joints"] = joints_list(c.joints);
  py::list patterns;
  for (const ModelPattern& p : c.model_check.patterns) {
    py::dict pd;
    pd["kind"] = p.kind;
    pd["joint"] = p.joint;
    pd["share"] = p.share;
    pd["message"] = p.message;
    patterns.append(pd);
  }
  d["patterns"] = patterns;
  py::list windows;
  for (const SuspectWindow& w : c.suspect_windows) {
    py::dict wd;
    wd["t_begin"] = w.t_begin;
    wd["t_end"] = w.t_end;
    wd["joint"] = w.joint;
    wd["peak"] = w.peak;
    windows.append(wd);
  }
  d["suspect_windows"] = windows;
  d["warnings"] = c.warnings;
  d["holdout"] = holdout_dict(run.holdout);
  d["yaml"] = yaml;
  d["report"] = calibration_report(run, known_torque);
  return d;
}

}  // namespace

void bind_app(py::module_& m) {
  m.def("calibrate", &calibrate_py, py::arg("estimator"), py::arg("log"), py::kw_only(),
        py::arg("holdout") = 0.0, py::arg("sign") = "tanh", py::arg("smoothing_velocity") = 0.0,
        py::arg("presliding_displacement") = 0.0, py::arg("false_alarms_per_hour") = 1.0,
        py::arg("thresholds") = "auto", py::arg("payload") = false, py::arg("known_torque") = false,
        py::arg("inertia") = false, py::arg("ignore_extra_joints") = false,
        py::arg("out") = py::none(),
        R"(Calibrates the estimator's configuration from a contact-free log, as `extwrench
calibrate --config CONFIG --log LOG` does (docs/calibration.md): friction, torque offsets, sensor
bias, residual noise and thresholds, fitted on the first (1 - holdout) of the log's rows and,
with holdout > 0, judged on the rest. The keywords are the command's options. Returns a dict:
friction, tau_min, tau_per_speed, f_min, sensor_bias, the per-joint fit report ('joints'), the
model check's 'patterns', 'warnings', 'holdout' (None without one) and 'yaml', the CALIB.yaml
text, also written to `out` when given; include it with {'calibration': path} in a config.)");
  m.def("_run_scenario", &run_scenario_py, py::arg("scenario"), py::arg("out_dir"),
        py::arg("figures") = false, py::arg("package_path") = std::vector<std::filesystem::path>{});
}

}  // namespace extwrench::python
