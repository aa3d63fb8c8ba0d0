// extwrench calibrate: friction, offsets, sensor bias, noise and thresholds from a contact-free
// log (docs/calibration.md), written as CALIB.yaml for `calibration:` in a configuration.
#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "extwrench/calibration/holdout.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/calibration_file.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/log.hpp"

namespace extwrench::cli {
namespace {

struct CalibrateOptions {
  std::filesystem::path config, log, out;
  double holdout = 0.0;
  std::string sign = "tanh";
  double smoothing_velocity = 0.0;
  double false_alarms_per_hour = 1.0;
  std::vector<std::filesystem::path> package_path;
};

std::vector<Sample> read_log(const std::filesystem::path& path, const Model& model) {
  LogReader reader(path, model);
  std::vector<Sample> samples;
  Sample s;
  while (reader.next(s)) samples.push_back(s);
  return samples;
}

void print_report(const Calibration& c, const HoldoutReport* h) {
  std::cout << "  joint  viscous  coulomb   offset   v_s    rms before -> after  var.expl  "
               "threshold\n";
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const JointFitReport& j = c.joints[i];
    std::cout << "  " << i + 1 << "      " << fmt(c.friction.viscous[k]) << "  "
              << fmt(c.friction.coulomb[k]) << "  " << fmt(c.friction.offset[k]) << "  "
              << fmt(c.friction.smoothing(k)) << "  " << fmt(j.rms_before) << " -> "
              << fmt(j.rms_after) << "  " << fmt(j.variance_explained) << "  " << fmt(j.threshold)
              << (j.threshold_from_max ? " (largest residual)" : " (gaussian)") << "\n";
  }
  if (c.sensor_type != SensorType::kNone) {
    std::cout << "  sensor bias [f; n] (S): " << fmt(Vector3(c.sensor_bias_S.head<3>())) << " N, "
              << fmt(Vector3(c.sensor_bias_S.tail<3>())) << " N m; F_min " << fmt(c.force_threshold)
              << " N\n";
  }
  for (const std::string& w : c.warnings)
    std::cerr << "extwrench calibrate: warning: " << w << "\n";
  if (h == nullptr) return;
  std::cout << "  holdout: " << h->samples << " samples (" << fmt(h->duration)
            << " s): " << h->false_alarms << " false-alarm samples ("
            << fmt(h->samples ? 100.0 * h->false_alarms / h->samples : 0.0) << " %), uncalibrated "
            << h->uncalibrated_false_alarms << "\n"
            << "  joint  calibrated threshold | smallest quiet constant: uncalibrated  "
               "calibrated\n";
  for (Eigen::Index i = 0; i < h->calibrated_threshold.size(); ++i)
    std::cout << "  " << i + 1 << "      " << fmt(h->calibrated_threshold[i]) << " | "
              << fmt(h->best_constant_threshold[i]) << "  " << fmt(h->calibrated_max_residual[i])
              << "\n";
  std::cout << "  link   smallest detectable force at " << fmt(h->lever)
            << " m [N] (median): calibrated thresholds | smallest quiet constant: uncalibrated  "
               "calibrated\n";
  for (std::size_t l = 1; l < h->min_force_calibrated.size(); ++l)
    std::cout << "  " << l << "      " << fmt(h->min_force_calibrated[l]) << " | "
              << fmt(h->min_force_constant[l]) << "  " << fmt(h->min_force_calibrated_quiet[l])
              << "\n";
}

void run_calibrate(const CalibrateOptions& opt) {
  if (!(opt.holdout >= 0.0 && opt.holdout < 1.0))
    throw UsageError("--holdout: expected a fraction in [0, 1)");
  CalibrationOptions co;
  if (opt.sign == "tanh") {
    co.sign = SmoothSign::kTanh;
  } else if (opt.sign == "sigmoid") {
    co.sign = SmoothSign::kSigmoid;
  } else {
    throw UsageError("--sign: expected tanh or sigmoid, got '" + opt.sign + "'");
  }
  if (opt.smoothing_velocity < 0) throw UsageError("--smoothing-velocity: expected a value >= 0");
  if (!(opt.false_alarms_per_hour > 0))
    throw UsageError("--false-alarms-per-hour: expected a value > 0");
  co.smoothing_velocity = opt.smoothing_velocity;
  co.false_alarms_per_hour = opt.false_alarms_per_hour;
  LoadOptions load;
  load.package_path = opt.package_path;
  const EstimatorConfig config = load_estimator_config(opt.config, load);
  check_input_file(opt.log, "log");
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Sample> samples = read_log(opt.log, config.robot.model);
  const auto fit_count =
      static_cast<std::size_t>(static_cast<double>(samples.size()) * (1.0 - opt.holdout));
  const std::vector<Sample> fit(samples.begin(),
                                samples.begin() + static_cast<std::ptrdiff_t>(fit_count));
  Calibration cal;
  try {
    cal = calibrate(config.robot.model, config.options, fit, co);
  } catch (const Error& e) {
    throw Error(opt.log.string() + ": " + e.what());
  }
  cal.source = opt.log.string();
  std::optional<HoldoutReport> holdout;
  if (opt.holdout > 0)
    holdout = validate_holdout(config.robot.model, config.options, cal, samples, fit_count);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ofstream out(opt.out);
  if (!out) throw Error(opt.out.string() + ": cannot write");
  out << calibration_to_yaml(cal, holdout ? &*holdout : nullptr);
  if (!out) throw Error(opt.out.string() + ": write failed");
  std::cout << "extwrench calibrate: " << samples.size() << " rows, fit on " << fit.size() << " ("
            << cal.samples_used << " used) in " << fmt(seconds) << " s -> " << opt.out.string()
            << "\n";
  print_report(cal, holdout ? &*holdout : nullptr);
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
  sub->add_option("--holdout", opt->holdout,
                  "Fit on the first 1 - FRACTION of the log, report false alarms and detectable "
                  "forces on the rest (default 0)")
      ->type_name("FRACTION");
  sub->add_option("--sign", opt->sign, "Smooth sign of the Coulomb term: tanh | sigmoid")
      ->type_name("MODEL");
  sub->add_option("--smoothing-velocity", opt->smoothing_velocity,
                  "Coulomb smoothing velocity [rad/s] (default: chosen per joint)")
      ->type_name("V");
  sub->add_option("--false-alarms-per-hour", opt->false_alarms_per_hour,
                  "False-alarm rate the thresholds are set for (default 1)")
      ->type_name("RATE");
  add_package_path_option(*sub, opt->package_path);
  sub->callback([opt]() { run_calibrate(*opt); });
}

}  // namespace extwrench::cli
