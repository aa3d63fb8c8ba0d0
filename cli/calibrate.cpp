// extwrench calibrate: friction, offsets, sensor bias, noise and thresholds from a contact-free
// log (docs/calibration.md), written as CALIB.yaml for `calibration:` in a configuration.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "commands.hpp"
#include "extwrench/app/calibrate_log.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/estimator_config.hpp"

namespace extwrench::cli {
namespace {

struct CalibrateOptions {
  std::filesystem::path config, log, out;
  CalibrateArguments arguments;
  std::vector<std::filesystem::path> package_path;
};

// "smoothing_velocity" -> "--smoothing-velocity"; values as typed; "--sign dahl".
std::string option_name(std::string_view key) {
  std::string name = "--" + std::string(key);
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}
std::string option_value(std::string_view text) { return std::string(text); }
constexpr ArgumentSpelling kOptionSpelling{option_name, option_value, " "};

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

void print_report(const Calibration& c, const HoldoutReport* h, bool in_contact) {
  const bool dahl = c.friction.sign == SmoothSign::kDahl;
  std::cout << "  joint  viscous  Coulomb   offset  " << (dahl ? "delta_q" : "    v_s")
            << "  RMS before ->  after  var.expl  threshold [N m]\n";
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const JointFitReport& j = c.joints[i];
    std::cout << "  " << std::left << std::setw(5) << i + 1 << std::right
              << cell(c.friction.viscous[k]) << " " << cell(c.friction.coulomb[k]) << " "
              << cell(c.friction.offset[k]) << " "
              << cell(dahl ? c.friction.presliding[k] : c.friction.smoothing(k)) << "  "
              << cell(j.rms_before) << " -> " << cell(j.rms_after, 6) << "  "
              << cell(j.variance_explained) << "  " << cell(j.threshold, 0);
    if (j.speed_dependent)
      std::cout << " + " << cell(j.threshold_per_speed, 0) << " |dq| (constant would be "
                << cell(j.threshold_constant, 0) << ")";
    std::cout << (j.threshold_from_max ? " (largest residual)" : " (gaussian)") << "\n";
  }
  if ((c.residual_cutoff.array() > 0.0).any()) {
    std::cout << "  residual filter [Hz]:";
    for (Eigen::Index i = 0; i < c.residual_cutoff.size(); ++i)
      std::cout << " " << cell(c.residual_cutoff[i], 0);
    std::cout << " (RMS, noise and thresholds are of the filtered residual)\n";
  }
  if (c.inertia_correction.size() > 0 && !c.inertia_correction.isZero(0.0)) {
    std::cout << "  inertia correction [kg m^2] (p = B(q) dq + dI dq):";
    for (Eigen::Index i = 0; i < c.inertia_correction.size(); ++i)
      std::cout << " " << cell(c.inertia_correction[i], 0);
    std::cout << "\n";
  }
  if (c.sensor_type != SensorType::kNone) {
    std::cout << "  sensor bias [f; n] (S): " << cells(Vector3(c.sensor_bias_S.head<3>())) << " N, "
              << cells(Vector3(c.sensor_bias_S.tail<3>())) << " N m; F_min "
              << cell(c.force_threshold, 0) << " N\n";
  }
  if (c.payload.identified) {
    std::cout << "  payload on link " << c.payload.body << ": " << cell(c.payload.mass, 0)
              << " kg, CoM " << cells(c.payload.com) << " m (link frame); sensor RMS per axis "
              << cells(Vector3(c.payload.rms_before.head<3>())) << " N "
              << cells(Vector3(c.payload.rms_before.tail<3>())) << " N m -> "
              << cells(Vector3(c.payload.rms_after.head<3>())) << " N "
              << cells(Vector3(c.payload.rms_after.tail<3>())) << " N m\n";
  }
  std::cout << "  model check: residual RMS per joint before calibration [";
  for (Eigen::Index i = 0; i < c.model_check.joint_rms.size(); ++i)
    std::cout << (i ? " " : "") << cell(c.model_check.joint_rms[i], 0);
  std::cout << "] N m";
  if (c.sensor_type != SensorType::kNone)
    std::cout << "; sensor error RMS " << cells(Vector3(c.model_check.sensor_rms.head<3>()))
              << " N " << cells(Vector3(c.model_check.sensor_rms.tail<3>())) << " N m";
  std::cout << "\n";
  for (const ModelPattern& p : c.model_check.patterns) std::cout << "    " << p.message << "\n";
  if (c.model_check.patterns.empty()) std::cout << "    no recognisable model error\n";
  for (const std::string& w : c.warnings)
    std::cerr << "extwrench calibrate: warning: " << w << "\n";
  if (h == nullptr) return;
  std::cout << "  holdout: " << h->samples << " samples (" << cell(h->duration, 0)
            << " s): " << h->false_alarms
            << (in_contact ? " samples with contact declared (the log is in contact: not false "
                             "alarms) ("
                           : " false-alarm samples (")
            << cell(h->samples ? 100.0 * h->false_alarms / h->samples : 0.0, 0)
            << " %), uncalibrated " << h->uncalibrated_false_alarms
            << ", calibrated with constant thresholds " << h->constant_threshold_false_alarms
            << "\n"
            << "  joint " << std::setw(22) << "calibrated threshold"
            << " | smallest quiet constant: " << std::setw(12) << "uncalibrated" << std::setw(12)
            << "calibrated"
            << "  [N m]\n";
  for (Eigen::Index i = 0; i < h->calibrated_threshold.size(); ++i)
    std::cout << "  " << std::left << std::setw(6) << i + 1 << std::right
              << cell(h->calibrated_threshold[i], 22) << " | " << std::setw(26) << ""
              << cell(h->best_constant_threshold[i], 12) << cell(h->calibrated_max_residual[i], 12)
              << "\n";
  std::cout << "  smallest force detectable at " << cell(h->lever, 0)
            << " m [N] (median over the holdout), with\n"
            << "  link " << std::setw(23) << "calibrated thresholds" << std::setw(16)
            << "(constant form)"
            << " | smallest quiet constant: " << std::setw(12) << "uncalibrated" << std::setw(12)
            << "calibrated"
            << "\n";
  for (std::size_t l = 1; l < h->min_force_calibrated.size(); ++l)
    std::cout << "  " << std::left << std::setw(5) << l << std::right
              << cell(h->min_force_calibrated[l], 23)
              << cell(h->min_force_calibrated_constant[l], 16) << " | " << std::setw(26) << ""
              << cell(h->min_force_constant[l], 12) << cell(h->min_force_calibrated_quiet[l], 12)
              << "\n";
  if (h->tracking_rms_calibrated.size() == 0) return;
  std::cout << "  joint  RMS of residual - true_tau_ext on the holdout [N m]: uncalibrated -> "
               "calibrated\n";
  for (Eigen::Index i = 0; i < h->tracking_rms_calibrated.size(); ++i)
    std::cout << "  " << std::left << std::setw(5) << i + 1 << std::right
              << cell(h->tracking_rms_uncalibrated[i]) << " -> "
              << cell(h->tracking_rms_calibrated[i]) << "\n";
}

void run_calibrate(const CalibrateOptions& opt) {
  CalibrationOptions co;
  try {
    co = calibration_options(opt.arguments, kOptionSpelling);
  } catch (const Error& e) {
    throw UsageError(e.what());  // a bad option: exit code 2
  }
  LoadOptions load;
  load.package_path = opt.package_path;
  const EstimatorConfig config = load_estimator_config(opt.config, load);
  const auto start = std::chrono::steady_clock::now();
  const CalibrateLogResult run = calibrate_log(config, opt.log, co, opt.arguments.holdout);
  const Calibration& cal = run.calibration;
  const HoldoutReport* holdout = run.holdout ? &*run.holdout : nullptr;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_calibration(opt.out, calibration_yaml(run));
  std::cout << "extwrench calibrate: " << run.rows << " rows, fit on " << run.fit_rows << " ("
            << cal.samples_used << " used) in " << cell(seconds, 0) << " s -> " << opt.out.string()
            << "\n";
  print_report(cal, holdout, opt.arguments.known_torque);
}

}  // namespace

void register_calibrate(CLI::App& app) {
  auto opt = std::make_shared<CalibrateOptions>();
  CLI::App* sub = app.add_subcommand(
      "calibrate",
      "Identify friction, torque offsets, sensor bias, noise and thresholds from a contact-free "
      "log; write CALIB.yaml for `calibration:` in a configuration (docs/calibration.md)");
  sub->add_option("--config", opt->config, "Estimator configuration (YAML, docs/config.md)")
      ->required()
      ->type_name("CONFIG.yaml");
  sub->add_option("--log", opt->log, "Contact-free robot log (CSV, docs/log_format.md)")
      ->required()
      ->type_name("FREE.csv");
  sub->add_option("--out", opt->out, "Calibration file to write")
      ->required()
      ->type_name("CALIB.yaml");
  sub->add_option("--holdout", opt->arguments.holdout,
                  "Fit on the first 1 - FRACTION of the log, report false alarms and detectable "
                  "forces on the rest (default 0)")
      ->type_name("FRACTION");
  sub->add_option("--sign", opt->arguments.sign,
                  "Sign of the Coulomb term: tanh | sigmoid (of the velocity) | dahl (lags a "
                  "reversal by a presliding displacement; docs/calibration.md)")
      ->type_name("MODEL");
  sub->add_option("--smoothing-velocity", opt->arguments.smoothing_velocity,
                  "Coulomb smoothing velocity [rad/s] (default: chosen per joint)")
      ->type_name("V");
  sub->add_option("--presliding-displacement", opt->arguments.presliding_displacement,
                  "With --sign dahl: presliding displacement [rad] (default: chosen per joint "
                  "from 0.5 to 10 mrad)")
      ->type_name("D");
  sub->add_option("--false-alarms-per-hour", opt->arguments.false_alarms_per_hour,
                  "False-alarm rate the thresholds are set for (default 1)")
      ->type_name("RATE");
  sub->add_option("--thresholds", opt->arguments.thresholds,
                  "Joint thresholds: constant (a), speed (a + b|dq| on every joint) or auto "
                  "(a + b|dq| where it is lower on average over the motion; default)")
      ->type_name("FORM");
  sub->add_flag("--payload", opt->arguments.payload,
                "Identify a payload (mass, CoM) on the last link from the base F/T sensor and add "
                "it to the model (needs sensor.type: ft)");
  sub->add_flag("--known-torque", opt->arguments.known_torque,
                "The log is not contact-free but its true_tau_ext1..n columns hold the external "
                "torque known during the recording (e.g. J_v^T F of a force plate under the "
                "contact): it is taken out of the residual before the fit (needs sensor.type: "
                "none)");
  sub->add_flag("--inertia", opt->arguments.inertia,
                "Also fit a correction of the inertia along each joint (observer.inertia_"
                "correction), kept where it lowers the joint's residual by 10 % or more beyond a "
                "gravity error; best with observer.residual_cutoff on noisy joints");
  add_package_path_option(*sub, opt->package_path);
  sub->callback([opt]() { run_calibrate(*opt); });
}

}  // namespace extwrench::cli
