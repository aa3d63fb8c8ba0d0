// extwrench calibrate: friction, offsets, sensor bias, noise and thresholds from a contact-free
// log (docs/calibration.md), written as CALIB.yaml for `calibration:` in a configuration.
#include <algorithm>
#include <chrono>
#include <cstdio>
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
  std::vector<std::string> lock;
  std::string root_body, tip_body;  ///< MJCF only
};

// "smoothing_velocity" -> "--smoothing-velocity"; values as typed; "--sign dahl".
std::string option_name(std::string_view key) {
  std::string name = "--" + std::string(key);
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}
std::string option_value(std::string_view text) { return std::string(text); }
constexpr ArgumentSpelling kOptionSpelling{option_name, option_value, " "};

void run_calibrate(const CalibrateOptions& opt) {
  CalibrationOptions co;
  try {
    co = calibration_options(opt.arguments, kOptionSpelling);
  } catch (const Error& e) {
    throw UsageError(e.what());  // a bad option: exit code 2
  }
  refuse_dash(opt.out, "--out",
              "calibrate writes CALIB.yaml to a file, not to standard output (its report goes "
              "there); give a file path");
  check_output_file(opt.out, "--out", {opt.config, opt.log});
  const LoadOptions load =
      robot_load_options(opt.package_path, opt.lock, opt.root_body, opt.tip_body);
  const EstimatorConfig config = load_estimator_config(opt.config, load);
  const auto start = std::chrono::steady_clock::now();
  const CalibrateLogResult run =
      calibrate_log(config, opt.log, co, opt.arguments.holdout, opt.arguments.ignore_extra_joints);
  const Calibration& cal = run.calibration;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_calibration(opt.out, calibration_yaml(run));
  char took[32];
  std::snprintf(took, sizeof took, "%.4g", seconds);
  std::cout << "extwrench calibrate: " << run.rows << " rows, fit on " << run.fit_rows << " ("
            << cal.samples_used << " used) in " << took << " s -> " << opt.out.string() << "\n"
            << calibration_report(run, opt.arguments.known_torque) << std::flush;
  for (const std::string& w : cal.warnings)
    std::cerr << "extwrench calibrate: warning: " << w << "\n";
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
                "it to the model (needs sensor.type: ft or force)");
  sub->add_flag("--known-torque", opt->arguments.known_torque,
                "The log is not contact-free but its true_tau_ext1..n columns hold the external "
                "torque known during the recording (e.g. J_v^T F of a force plate under the "
                "contact): it is taken out of the residual before the fit (needs sensor.type: "
                "none)");
  sub->add_flag("--inertia", opt->arguments.inertia,
                "Also fit a correction of the inertia along each joint (observer.inertia_"
                "correction), kept where it lowers the joint's residual by 10 % or more beyond "
                "the velocity's noise and a gravity error; best with observer.velocity_cutoff on "
                "joints whose dq is noisy");
  sub->add_flag("--ignore-extra-joints", opt->arguments.ignore_extra_joints,
                "Ignore joint columns beyond the robot's n (q8, tau8 of a gripper on a 7-joint "
                "arm); without it they are an error, as for estimate");
  add_package_path_option(*sub, opt->package_path);
  add_lock_option(*sub, opt->lock);
  add_chain_options(*sub, opt->root_body, opt->tip_body);
  sub->footer(help_footer(
      {{"extwrench calibrate --config panda.yaml --log free.csv --out calib.yaml --holdout 0.4",
        "fit on the first 60 % of a contact-free log, report false alarms and the smallest "
        "detectable forces on the rest; then add `calibration: calib.yaml` to panda.yaml"},
       {"extwrench calibrate --config results/free/ft/config.yaml --log results/free/log.csv "
        "--out results/free/calib.yaml --holdout 0.4",
        "the rehearsal on `extwrench simulate scenarios/paper_free_motion.yaml --out "
        "results/free`"},
       {"extwrench calibrate --config leg.yaml --log push.csv --out calib.yaml --known-torque",
        "a log in contact whose true_tau_ext1..n columns hold the known external torque (a "
        "force plate's J_v^T F)"}},
      "docs/calibration.md (the procedure on a real robot), docs/cli.md (calibrate)"));
  sub->callback([opt]() { run_calibrate(*opt); });
}

}  // namespace extwrench::cli
