// Calibrating from a recorded log: the job of `extwrench calibrate` and of Python's
// extwrench.calibrate (docs/calibration.md): the log read for the configuration's robot, the
// calibration fitted on its first part and, with a holdout, judged on the rest.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>

#include "extwrench/calibration/calibration.hpp"
#include "extwrench/calibration/holdout.hpp"
#include "extwrench/io/estimator_config.hpp"

namespace extwrench {

struct CalibrateLogResult {
  std::size_t rows = 0;                  ///< samples in the log
  std::size_t fit_rows = 0;              ///< the first ones, given to calibrate()
  Calibration calibration;               ///< its source: the log's path
  std::optional<HoldoutReport> holdout;  ///< with a holdout fraction > 0
};

/// Reads `log` (docs/log_format.md) for the configuration's robot, calibrates (calibrate()) on
/// the first (1 − holdout) of its rows with the configuration's options and, when holdout > 0,
/// judges the calibration on the rest (validate_holdout()). Throws extwrench::Error naming the
/// log (its line for a malformed row) or, for a holdout outside [0, 1), the fraction.
[[nodiscard]] CalibrateLogResult calibrate_log(const EstimatorConfig& config,
                                               const std::filesystem::path& log,
                                               const CalibrationOptions& options, double holdout);

}  // namespace extwrench
