#include "extwrench/app/calibrate_log.hpp"

#include <string>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench {

CalibrateLogResult calibrate_log(const EstimatorConfig& config, const std::filesystem::path& log,
                                 const CalibrationOptions& options, double holdout) {
  if (!(holdout >= 0.0 && holdout < 1.0))
    throw Error("holdout: expected a fraction in [0, 1), got " + format_number(holdout));
  check_input_file(log, "log");
  const Model& model = config.robot.model;
  std::vector<Sample> samples;
  {
    LogReader reader(log, model);
    for (Sample s; reader.next(s);) samples.push_back(s);
  }
  CalibrateLogResult result;
  result.rows = samples.size();
  result.fit_rows = static_cast<std::size_t>(static_cast<double>(samples.size()) * (1.0 - holdout));
  const std::vector<Sample> fit(samples.begin(),
                                samples.begin() + static_cast<std::ptrdiff_t>(result.fit_rows));
  try {
    result.calibration = calibrate(model, config.options, fit, options);
  } catch (const Error& e) {
    throw Error(log.string() + ": " + e.what());
  }
  result.calibration.source = log.string();
  if (holdout > 0)
    result.holdout =
        validate_holdout(model, config.options, result.calibration, samples, result.fit_rows);
  return result;
}

}  // namespace extwrench
