// Calibrating from a recorded log: the job of `extwrench calibrate` and of Python's
// extwrench.calibrate (docs/calibration.md): the log read for the configuration's robot, the
// calibration fitted on its first part and, with a holdout, judged on the rest.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "extwrench/calibration/calibration.hpp"
#include "extwrench/calibration/holdout.hpp"
#include "extwrench/io/estimator_config.hpp"

namespace extwrench {

/// A calibration's options as a user gives them: `extwrench calibrate`'s options, Python's
/// calibrate keywords (docs/calibration.md).
struct CalibrateArguments {
  double holdout = 0.0;  ///< share of the log judged, not fitted, in [0, 1)
  std::string sign = "tanh";
  double smoothing_velocity = 0.0;       ///< v_s [rad/s], not with dahl; 0: per joint
  double presliding_displacement = 0.0;  ///< δ [rad], dahl only; 0: per joint
  double false_alarms_per_hour = 1.0;
  std::string thresholds = "auto";
  bool payload = false;
  bool known_torque = false;
  bool inertia = false;
  bool ignore_extra_joints = false;  ///< joint columns beyond the robot's n are not an error
};

/// How a front end spells its arguments in messages: an argument's name from its key
/// ("smoothing_velocity" -> "--smoothing-velocity"), a value ("dahl" -> "'dahl'"), and what joins
/// a name to its value ("--sign dahl", "sign='dahl'").
struct ArgumentSpelling {
  std::string (*name)(std::string_view key);
  std::string (*value)(std::string_view text);
  std::string_view assign;
};

/// The CalibrationOptions of checked arguments. Throws extwrench::Error "NAME: what" for the
/// first bad one: a holdout outside [0, 1), an unknown sign or threshold form, a negative (or
/// NaN) smoothing velocity or presliding displacement, either one with the other sign, a
/// false-alarm rate not > 0.
[[nodiscard]] CalibrationOptions calibration_options(const CalibrateArguments& arguments,
                                                     const ArgumentSpelling& spelling);

struct CalibrateLogResult {
  std::size_t rows = 0;                  ///< samples in the log
  std::size_t fit_rows = 0;              ///< the first ones, given to calibrate()
  Calibration calibration;               ///< its source: the log's path
  std::optional<HoldoutReport> holdout;  ///< with a holdout fraction > 0
};

/// Reads `log` (docs/log_format.md) for the configuration's robot, calibrates (calibrate()) on
/// the first (1 − holdout) of its rows with the configuration's options and, when holdout > 0,
/// judges the calibration on the rest (validate_holdout()). Throws extwrench::Error naming the
/// log (its line for a malformed row) or, for a holdout outside [0, 1), the fraction. The log's
/// header is checked as `extwrench estimate` checks it: joint columns beyond the robot's n are
/// an error unless `ignore_extra_joint_columns`, the configured sensor's columns must be there.
/// A log whose truth columns (true_link) mark a contact on more than
/// CalibrationOptions::max_contact_fraction of the fitted rows is refused unless the external
/// torque is known (known_external_torque); a smaller share is warned about.
[[nodiscard]] CalibrateLogResult calibrate_log(const EstimatorConfig& config,
                                               const std::filesystem::path& log,
                                               const CalibrationOptions& options, double holdout,
                                               bool ignore_extra_joint_columns = false);

/// The report `extwrench calibrate` prints under its first line (Python's calibrate returns it
/// as "report"): per joint the friction, the residual's RMS before and after, the variance
/// explained and the threshold; the residual filter, inertia correction, sensor bias and payload
/// when there are any; the model check; with a holdout, its false alarms, thresholds and the
/// smallest forces detectable per link. `in_contact`: the log holds a known contact
/// (--known-torque), so its contact samples are not called false alarms. Four significant
/// digits (CALIB.yaml has the exact values); the warnings are not in it (Calibration::warnings).
[[nodiscard]] std::string calibration_report(const CalibrateLogResult& run, bool in_contact);

/// The CALIB.yaml text of a run: calibration_to_yaml with its holdout report.
[[nodiscard]] std::string calibration_yaml(const CalibrateLogResult& run);

/// Writes CALIB.yaml text to `path` as one transaction (io/output_files.hpp: written as
/// "<path>.partial", renamed when complete; missing directories created), so a failed write
/// leaves no truncated calibration for a configuration to include, and an earlier file of that
/// name as it was. Throws extwrench::Error naming the file.
void write_calibration(const std::filesystem::path& path, std::string_view yaml);

}  // namespace extwrench
