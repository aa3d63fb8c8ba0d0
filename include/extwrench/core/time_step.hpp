// Time steps: the shortest an estimator accepts, a log's time column taken as seconds (the one
// rule by which `estimate` notes a log and `calibrate` refuses it), and a time in a message.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace extwrench {

/// The shortest time step [s] between two samples an estimator accepts: 1 ns. A step below it
/// (a repeated or subnormally close time stamp) is kNonIncreasingTime: divided by, it would make
/// the residual NaN for good.
inline constexpr double kShortestTimeStep = 1e-9;

/// The longest mean time step [s] of a log taken as timed in seconds: 50 ms (20 Hz, where a
/// robot's controller logs at 100 Hz to 1 kHz). Beyond it t is likely in milliseconds or counts
/// samples: `estimate` notes it (time_step_note), `calibrate` refuses the log.
inline constexpr double kLongestMeanTimeStep = 0.05;

/// For `samples` time stamps from t_first to t_last more than kLongestMeanTimeStep apart on
/// average: "the samples are 1.073 s apart on average (0.932 Hz): t must be in seconds
/// (docs/log_format.md)"; else empty (and below two samples).
[[nodiscard]] inline std::string slow_time_step(double t_first, double t_last, long samples) {
  if (samples < 2) return {};
  const double step = (t_last - t_first) / static_cast<double>(samples - 1);
  if (!(step > kLongestMeanTimeStep)) return {};
  char text[128];
  std::snprintf(text, sizeof text,
                "the samples are %.4g s apart on average (%.3g Hz): t must be in seconds "
                "(docs/log_format.md)",
                step, 1.0 / step);
  return text;
}

/// A log's time in a message: six significant digits ("0.999", "12.3457"), but to the
/// millisecond from 1000 s on, where a log is stamped by a clock's epoch ("1765140000.999"; six
/// digits read "1.76514e+09" for every row of a day).
[[nodiscard]] inline std::string time_text(double t) {
  char text[40];
  std::snprintf(text, sizeof text, std::abs(t) >= 1e3 ? "%.3f" : "%.6g", t == 0.0 ? 0.0 : t);
  return text;
}

}  // namespace extwrench
