// Accuracy metrics of an estimator against the truth (docs/log_format.md, metrics.json),
// accumulated sample by sample in constant memory, over a stated time window.
#pragma once

#include <limits>
#include <utility>
#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/core/types.hpp"
#include "extwrench/estimation/contact_estimate.hpp"

namespace extwrench::sim {

/// Time window of a metric: [from, to] minus the excluded intervals.
struct MetricsWindow {
  double from = 0.0;
  double to = std::numeric_limits<double>::infinity();
  std::vector<std::pair<double, double>> exclude;
  [[nodiscard]] bool contains(double t) const noexcept;
};

/// RMS and max of an error over the samples where it was evaluated.
struct ErrorStat {
  long count = 0;
  double sum_sq = 0.0;
  double max = 0.0;
  void add(double e) noexcept;
  [[nodiscard]] double rms() const noexcept;
};

struct Metrics {
  MetricsWindow window;
  long samples = 0;          ///< samples in the window
  long contact_samples = 0;  ///< in contact (single contact) in the window
  long free_samples = 0;
  /// ‖F̂ − F‖ over every sample of the window where the estimator gave a force (F̂ = 0 when it
  /// reports no contact, F = 0 when free).
  ErrorStat force;
  /// ‖M̂ − M‖, same rule with the moment; empty (count 0) unless the estimator gave a moment on
  /// some sample: a configuration that estimates none has no moment error to report.
  ErrorStat moment;
  /// Distance from the true point to the estimated line of action (in-contact samples with a line).
  ErrorStat line;
  /// ‖p_c − p‖, in-contact samples with a surface point (meaningful when p lies on the surface).
  ErrorStat surface;
  long force_not_estimated = 0;  ///< contact reported but no force estimated
  long line_not_estimated = 0;   ///< in contact, no line of action
  long right_link = 0;           ///< in contact, detected on the right link
  long missed = 0;               ///< in contact, not detected
  long false_alarms = 0;         ///< free, contact reported
  /// ... of which the release: the uninterrupted declared contact right after a true contact
  /// ended (the residual decaying), not a new alarm.
  long false_alarms_release = 0;
  // Uncertainty (issue 9): in-contact samples (single contact) with a force and its σ.
  long sigma_samples = 0;                ///< ... of which counted below
  long force_within_two_sigma = 0;       ///< ‖F̂ − F‖ ≤ 2 sigma_force
  long uncertain = 0;                    ///< flagged `uncertain`
  long large_force_error_unflagged = 0;  ///< ‖F̂ − F‖ > 0.5 ‖F‖ without `uncertain`
  // Detection delay: over the whole log (not windowed), from each onset of contact.
  long onsets = 0;
  long onsets_detected = 0;
  /// Onsets at which a contact declared on the sample before is still declared (a false alarm,
  /// or an earlier contact's release): no delay is measured for them.
  long onsets_already_declared = 0;
  double delay_sum = 0.0;
  double delay_max = 0.0;

  [[nodiscard]] double isolation_accuracy() const noexcept;  ///< right_link / contact_samples
  [[nodiscard]] double false_alarm_rate() const noexcept;    ///< false_alarms / free_samples
  /// force_within_two_sigma / sigma_samples (NaN without such samples).
  [[nodiscard]] double force_two_sigma_coverage() const noexcept;
  [[nodiscard]] double mean_detection_delay() const noexcept;
};

/// Feeds samples in time order; result() can be read at any point.
class MetricsAccumulator {
 public:
  explicit MetricsAccumulator(MetricsWindow window);
  /// One sample: the truth (in contact when truth.body >= 0) and what the estimator said (its
  /// flags say which quantities it produced; world frame).
  void add(double t, const Truth& truth, const ContactEstimate& estimate) noexcept;
  [[nodiscard]] Metrics result() const;

 private:
  Metrics m_;
  ErrorStat moment_undetected_;  // M's norm where no contact was declared (merged if estimated)
  bool moment_estimated_ = false;
  bool in_contact_ = false;
  bool declared_ = false;   // the estimator declared contact on the previous sample
  bool releasing_ = false;  // declared without a break since the last true contact ended
  bool waiting_detection_ = false;
  double onset_t_ = 0.0;
};

/// Distance from point p to the line through a with unit direction u.
[[nodiscard]] double point_line_distance(const Vector3& p, const Vector3& a,
                                         const Vector3& u) noexcept;

}  // namespace extwrench::sim
