#include "extwrench/app/calibrate_log.hpp"

#include <string>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/io/calibration_file.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/output_files.hpp"

namespace extwrench {
namespace {

[[noreturn]] void fail(const ArgumentSpelling& sp, std::string_view key, const std::string& what) {
  throw Error(sp.name(key) + ": " + what);
}

}  // namespace

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
  if (!(a.smoothing_velocity >= 0)) fail("smoothing_velocity", "expected a value >= 0");
  if (!(a.presliding_displacement >= 0)) fail("presliding_displacement", "expected a value >= 0");
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
