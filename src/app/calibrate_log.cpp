#include "extwrench/app/calibrate_log.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "extwrench/app/joint_range.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/core/time_step.hpp"
#include "extwrench/io/calibration_file.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/output_files.hpp"
#include "log_columns.hpp"

namespace extwrench {
namespace {

[[noreturn]] void fail(const ArgumentSpelling& sp, std::string_view key, const std::string& what) {
  throw Error(sp.name(key) + ": " + what);
}

}  // namespace

// Ten times the per-joint grid's largest δ (docs/calibration.md, the Dahl sign).
constexpr double kLargestPreslidingDisplacement = 0.1;

CalibrationOptions calibration_options(const CalibrateArguments& a, const ArgumentSpelling& sp) {
  const auto fail = [&](std::string_view key, const std::string& what) {
    extwrench::fail(sp, key, what);
  };
  const auto set_to = [&](std::string_view key, std::string_view value) {
    return sp.name(key) + std::string(sp.assign) + sp.value(value);
  };
  const auto one_of = [&](std::string_view x, std::string_view y, std::string_view z) {
    return sp.value(x) + ", " + sp.value(y) + " or " + sp.value(z);
  };
  if (!(a.holdout >= 0.0 && a.holdout < 1.0)) fail("holdout", "expected a fraction in [0, 1)");
  CalibrationOptions o;
  const std::optional<SmoothSign> sign = calibration_sign(a.sign);
  if (!sign)
    fail("sign", "expected " + one_of("tanh", "sigmoid", "dahl") + ", got '" + a.sign + "'");
  o.sign = *sign;
  const bool dahl = o.sign == SmoothSign::kDahl;
  if (dahl && a.smoothing_velocity > 0) {
    fail("smoothing_velocity", "not used with " + set_to("sign", "dahl") +
                                   " (its presliding displacement is chosen per joint, or fixed "
                                   "by " +
                                   sp.name("presliding_displacement") + ")");
  }
  if (!dahl && a.presliding_displacement > 0)
    fail("presliding_displacement", "only with " + set_to("sign", "dahl"));
  if (!(a.smoothing_velocity >= 0))
    fail("smoothing_velocity", "expected a value > 0 [rad/s], or 0 to choose it per joint");
  if (!(a.presliding_displacement >= 0))
    fail("presliding_displacement", "expected a value > 0 [rad], or 0 to choose it per joint");
  // Presliding is a few milliradians: a larger value is another unit (mrad, degrees).
  if (a.presliding_displacement > kLargestPreslidingDisplacement) {
    fail("presliding_displacement",
         "expected a displacement in rad of at most " +
             format_number(kLargestPreslidingDisplacement) +
             " (presliding is 0.5 to 10 mrad: " + "0.0005 to 0.01), got " +
             format_number(a.presliding_displacement) + ": is it in mrad or degrees?");
  }
  if (!(a.false_alarms_per_hour > 0)) fail("false_alarms_per_hour", "expected a value > 0");
  const std::optional<ThresholdModel> thresholds = threshold_model(a.thresholds);
  if (!thresholds) {
    fail("thresholds",
         "expected " + one_of("auto", "constant", "speed") + ", got '" + a.thresholds + "'");
  }
  o.thresholds = *thresholds;
  // The library's one fixed scale: v_s, or δ with the Dahl sign.
  o.smoothing_velocity = dahl ? a.presliding_displacement : a.smoothing_velocity;
  o.false_alarms_per_hour = a.false_alarms_per_hour;
  o.payload = a.payload;
  o.known_external_torque = a.known_torque;
  o.inertia_correction = a.inertia;
  return o;
}

namespace {

// A log that says itself it is in contact (true_link, a simulation's or a force plate's): more
// than the share of contact calibrate() tolerates is refused here, since a contact over most of
// the log escapes calibrate()'s own detection; less is returned as a warning.
std::optional<std::string> truth_contact_note(const std::vector<Sample>& fit,
                                              const CalibrationOptions& options,
                                              const std::filesystem::path& log) {
  std::size_t contact = 0;
  double first = 0.0, last = 0.0;
  for (const Sample& s : fit) {
    if (!s.has_truth || s.truth.body < 0) continue;
    if (contact++ == 0) first = s.t;
    last = s.t;
  }
  if (contact == 0) return std::nullopt;
  const double share = static_cast<double>(contact) / static_cast<double>(fit.size());
  const std::string what = "its truth column true_link marks a contact on " +
                           format_number(std::round(1000.0 * share) / 10.0) +
                           " % of the fitted rows (between t = " + format_number(first) + " and " +
                           format_number(last) + " s)";
  if (share > options.max_contact_fraction) {
    throw Error(log.string() + ": " + what + ": calibration needs a contact-free log (at most " +
                format_number(100.0 * options.max_contact_fraction) +
                " % in contact), or the external torque known during the recording in its "
                "true_tau_ext1..n columns (--known-torque; Python: known_torque=True)");
  }
  return what + ": the fit treats them as free motion unless its own detection excludes them";
}

}  // namespace

CalibrateLogResult calibrate_log(const EstimatorConfig& config, const std::filesystem::path& log,
                                 const CalibrationOptions& options, double holdout,
                                 bool ignore_extra_joint_columns) {
  if (!(holdout >= 0.0 && holdout < 1.0))
    throw Error("holdout: expected a fraction in [0, 1), got " + format_number(holdout));
  check_input_file(log, "log");
  const Model& model = config.robot.model;
  std::vector<Sample> samples;
  {
    LogReader reader(log, model);
    detail::check_joint_columns(reader, model.nq(), ignore_extra_joint_columns);
    detail::check_sensor_columns(reader, config.options.sensor.type);
    for (Sample s; reader.next(s);) samples.push_back(s);
  }
  // Positions in degrees fit friction and thresholds to nonsense (10 000 N m) without a word:
  // refused; a few rows outside (a glitch) are warned about.
  JointRangeCheck joint_range(model);
  for (const Sample& s : samples) joint_range.add(s);
  const std::string range = joint_range.note();
  if (joint_range.mostly_outside()) throw Error(log.string() + ": " + range);
  CalibrateLogResult result;
  result.rows = samples.size();
  result.fit_rows = static_cast<std::size_t>(static_cast<double>(samples.size()) * (1.0 - holdout));
  const std::vector<Sample> fit(samples.begin(),
                                samples.begin() + static_cast<std::ptrdiff_t>(result.fit_rows));
  const std::optional<std::string> truth_note =
      options.known_external_torque ? std::nullopt : truth_contact_note(fit, options, log);
  try {
    result.calibration = calibrate(model, config.options, fit, options);
  } catch (const Error& e) {
    // With a holdout the fit sees only the log's first part: say so, or "record a longer
    // motion" reads as if the whole log were too short.
    const std::string part =
        holdout > 0 && !fit.empty()
            ? " (the fit has the first " + std::to_string(fit.size()) + " of the log's " +
                  std::to_string(samples.size()) + " rows, t <= " + format_number(fit.back().t) +
                  " s: the holdout " + format_number(holdout) + " keeps the rest for judging)"
            : std::string();
    throw Error(log.string() + ": " + e.what() + part);
  }
  if (truth_note)
    result.calibration.warnings.insert(result.calibration.warnings.begin(), *truth_note);
  if (!range.empty())
    result.calibration.warnings.insert(result.calibration.warnings.begin(), range);
  result.calibration.source = log.string();
  if (holdout > 0)
    result.holdout =
        validate_holdout(model, config.options, result.calibration, samples, result.fit_rows);
  return result;
}

namespace {

// The report's numbers: four significant digits, right-aligned in `width` columns (the exact
// values are in CALIB.yaml).
std::string cell(double value, int width = 8) {
  std::array<char, 40> text{};
  std::snprintf(text.data(), text.size(), "%*.4g", width, value == 0.0 ? 0.0 : value);
  return text.data();
}

std::string cells(const Vector3& v) {
  return "(" + cell(v.x(), 0) + ", " + cell(v.y(), 0) + ", " + cell(v.z(), 0) + ")";
}

}  // namespace

std::string calibration_report(const CalibrateLogResult& run, bool in_contact) {
  const Calibration& c = run.calibration;
  const HoldoutReport* h = run.holdout ? &*run.holdout : nullptr;
  std::ostringstream out;
  const bool dahl = c.friction.sign == SmoothSign::kDahl;
  out << "  joint  viscous  Coulomb   offset  " << (dahl ? "delta_q" : "    v_s")
      << "  RMS before ->  after  var.expl  threshold [N m]\n";
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const JointFitReport& j = c.joints[i];
    out << "  " << std::left << std::setw(5) << i + 1 << std::right << cell(c.friction.viscous[k])
        << " " << cell(c.friction.coulomb[k]) << " " << cell(c.friction.offset[k]) << " "
        << cell(dahl ? c.friction.presliding[k] : c.friction.smoothing(k)) << "  "
        << cell(j.rms_before) << " -> " << cell(j.rms_after, 6) << "  "
        << cell(j.variance_explained) << "  " << cell(j.threshold, 0);
    if (j.speed_dependent)
      out << " + " << cell(j.threshold_per_speed, 0) << " |dq| (constant would be "
          << cell(j.threshold_constant, 0) << ")";
    if (j.threshold_from_max)
      out << " (largest residual, at t = " << time_text(j.max_after_t) << " s)\n";
    else
      out << " (gaussian)\n";
  }
  if ((c.residual_cutoff.array() > 0.0).any()) {
    out << "  residual filter [Hz]:";
    for (Eigen::Index i = 0; i < c.residual_cutoff.size(); ++i)
      out << " " << cell(c.residual_cutoff[i], 0);
    out << " (RMS, noise and thresholds are of the filtered residual)\n";
  }
  if ((c.velocity_cutoff.array() > 0.0).any()) {
    out << "  velocity filter [Hz]:";
    for (Eigen::Index i = 0; i < c.velocity_cutoff.size(); ++i)
      out << " " << cell(c.velocity_cutoff[i], 0);
    out << " (the observer's momentum takes the filtered dq, as the estimator's)\n";
  }
  if (c.inertia_correction.size() > 0 && !c.inertia_correction.isZero(0.0)) {
    out << "  inertia correction [kg m^2] (p = B(q) dq + dI dq):";
    for (Eigen::Index i = 0; i < c.inertia_correction.size(); ++i)
      out << " " << cell(c.inertia_correction[i], 0);
    out << "\n";
  }
  if (c.sensor_type != SensorType::kNone) {
    out << "  sensor bias [f; n] (S): " << cells(Vector3(c.sensor_bias_S.head<3>())) << " N, "
        << cells(Vector3(c.sensor_bias_S.tail<3>())) << " N m; F_min " << cell(c.force_threshold, 0)
        << " N\n";
  }
  if (c.payload.identified) {
    out << "  payload on link " << c.payload.body << ": " << cell(c.payload.mass, 0) << " kg, CoM "
        << cells(c.payload.com) << " m (link frame); sensor RMS per axis "
        << cells(Vector3(c.payload.rms_before.head<3>())) << " N "
        << cells(Vector3(c.payload.rms_before.tail<3>())) << " N m -> "
        << cells(Vector3(c.payload.rms_after.head<3>())) << " N "
        << cells(Vector3(c.payload.rms_after.tail<3>())) << " N m\n";
  }
  out << "  model check: residual RMS per joint before calibration [";
  for (Eigen::Index i = 0; i < c.model_check.joint_rms.size(); ++i)
    out << (i ? " " : "") << cell(c.model_check.joint_rms[i], 0);
  out << "] N m";
  if (c.sensor_type != SensorType::kNone)
    out << "; sensor error RMS " << cells(Vector3(c.model_check.sensor_rms.head<3>())) << " N "
        << cells(Vector3(c.model_check.sensor_rms.tail<3>())) << " N m";
  out << "\n";
  for (const ModelPattern& p : c.model_check.patterns) out << "    " << p.message << "\n";
  if (c.model_check.patterns.empty()) out << "    no recognisable model error\n";
  if (h == nullptr) return out.str();
  out << "  holdout: " << h->samples << " samples (" << cell(h->duration, 0)
      << " s): " << h->false_alarms
      << (in_contact ? " samples with contact declared (the log is in contact: not false "
                       "alarms) ("
                     : " false-alarm samples (")
      << cell(h->samples ? 100.0 * h->false_alarms / h->samples : 0.0, 0) << " %), uncalibrated "
      << h->uncalibrated_false_alarms << ", calibrated with constant thresholds "
      << h->constant_threshold_false_alarms << "\n"
      << "  joint " << std::setw(22) << "calibrated threshold"
      << " | smallest quiet constant: " << std::setw(12) << "uncalibrated" << std::setw(12)
      << "calibrated"
      << "  [N m]\n";
  for (Eigen::Index i = 0; i < h->calibrated_threshold.size(); ++i)
    out << "  " << std::left << std::setw(6) << i + 1 << std::right
        << cell(h->calibrated_threshold[i], 22) << " | " << std::setw(26) << ""
        << cell(h->best_constant_threshold[i], 12) << cell(h->calibrated_max_residual[i], 12)
        << "\n";
  out << "  smallest force detectable at " << cell(h->lever, 0)
      << " m [N] (median over the holdout), with\n"
      << "  link " << std::setw(23) << "calibrated thresholds" << std::setw(16) << "(constant form)"
      << " | smallest quiet constant: " << std::setw(12) << "uncalibrated" << std::setw(12)
      << "calibrated"
      << "\n";
  for (std::size_t l = 1; l < h->min_force_calibrated.size(); ++l)
    out << "  " << std::left << std::setw(5) << l << std::right
        << cell(h->min_force_calibrated[l], 23) << cell(h->min_force_calibrated_constant[l], 16)
        << " | " << std::setw(26) << "" << cell(h->min_force_constant[l], 12)
        << cell(h->min_force_calibrated_quiet[l], 12) << "\n";
  if (h->tracking_rms_calibrated.size() == 0) return out.str();
  out << "  joint  RMS of residual - true_tau_ext on the holdout [N m]: uncalibrated -> "
         "calibrated\n";
  for (Eigen::Index i = 0; i < h->tracking_rms_calibrated.size(); ++i)
    out << "  " << std::left << std::setw(5) << i + 1 << std::right
        << cell(h->tracking_rms_uncalibrated[i]) << " -> " << cell(h->tracking_rms_calibrated[i])
        << "\n";
  return out.str();
}

std::string calibration_yaml(const CalibrateLogResult& run) {
  return calibration_to_yaml(run.calibration, run.holdout ? &*run.holdout : nullptr);
}

void write_calibration(const std::filesystem::path& path, std::string_view yaml) {
  OutputFiles files;
  if (path.has_parent_path()) files.create_directories(path.parent_path());
  files.write_text(path, yaml);
  files.keep();
}

}  // namespace extwrench
