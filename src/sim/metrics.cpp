#include "extwrench/sim/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace extwrench::sim {
namespace {
constexpr double kLargeForceError = 0.5;  // share of ‖F‖ a force error must never reach unflagged
}  // namespace

bool MetricsWindow::contains(double t) const noexcept {
  if (t < from || t > to) return false;
  for (const auto& [a, b] : exclude) {
    if (t >= a && t <= b) return false;
  }
  return true;
}

void ErrorStat::add(double e) noexcept {
  ++count;
  sum_sq += e * e;
  if (e > max) max = e;
}

double ErrorStat::rms() const noexcept {
  return count > 0 ? std::sqrt(sum_sq / static_cast<double>(count)) : std::nan("");
}

double Metrics::isolation_accuracy() const noexcept {
  return contact_samples > 0
             ? static_cast<double>(right_link) / static_cast<double>(contact_samples)
             : std::nan("");
}
double Metrics::false_alarm_rate() const noexcept {
  return free_samples > 0 ? static_cast<double>(false_alarms) / static_cast<double>(free_samples)
                          : std::nan("");
}
double Metrics::force_two_sigma_coverage() const noexcept {
  return sigma_samples > 0
             ? static_cast<double>(force_within_two_sigma) / static_cast<double>(sigma_samples)
             : std::nan("");
}
double Metrics::mean_detection_delay() const noexcept {
  return onsets_detected > 0 ? delay_sum / static_cast<double>(onsets_detected) : std::nan("");
}

double point_line_distance(const Vector3& p, const Vector3& a, const Vector3& u) noexcept {
  const Vector3 d = p - a;
  return (d - d.dot(u) * u).norm();
}

MetricsAccumulator::MetricsAccumulator(MetricsWindow window) { m_.window = std::move(window); }

void MetricsAccumulator::add(double t, const Truth& truth, const ContactEstimate& est) noexcept {
  const bool touched = truth.body >= 0;
  // Detection delay, over the whole log: onset = first sample of a contact. A contact declared
  // before it and still at it is no detection of this one (it would count a zero delay).
  if (touched && !in_contact_) {
    ++m_.onsets;
    onset_t_ = t;
    const bool already = declared_ && est.contact;  // declared before, and not released
    waiting_detection_ = !already;
    if (already) ++m_.onsets_already_declared;
  }
  // The release: from a true contact's end, as long as the declared contact lasts.
  if (!touched && in_contact_) releasing_ = true;
  if (!est.contact || touched) releasing_ = false;
  in_contact_ = touched;
  declared_ = est.contact;
  if (!touched) waiting_detection_ = false;
  if (waiting_detection_ && est.contact) {
    const double delay = t - onset_t_;
    ++m_.onsets_detected;
    m_.delay_sum += delay;
    if (delay > m_.delay_max) m_.delay_max = delay;
    waiting_detection_ = false;
  }

  if (!m_.window.contains(t)) return;
  ++m_.samples;
  // Force and moment errors: no detection means F̂ = 0, M̂ = 0; free means F = 0, M = 0.
  const Vector3 f_true = touched ? truth.force_W : Vector3::Zero();
  const Vector3 m_true = touched ? truth.moment_W : Vector3::Zero();
  if (!est.contact) {
    m_.force.add(f_true.norm());
  } else if (est.has(EstimateFlag::kForce)) {
    m_.force.add((est.force_W - f_true).norm());
  } else {
    ++m_.force_not_estimated;
  }
  if (!est.contact) {
    moment_undetected_.add(m_true.norm());
  } else if (est.has(EstimateFlag::kMoment)) {
    moment_estimated_ = true;
    m_.moment.add((est.moment_W - m_true).norm());
  }

  if (!touched) {
    ++m_.free_samples;
    if (est.contact) ++m_.false_alarms;
    if (releasing_) ++m_.false_alarms_release;
    return;
  }
  if (truth.contacts > 1) return;  // several contacts: link, line and point are not single-valued
  ++m_.contact_samples;
  if (!est.contact) {
    ++m_.missed;
  } else if (est.link == truth.body) {
    ++m_.right_link;
  }
  // A log without the true point (no true_p* columns: NaN) has no line or point error to count.
  const bool point_known = truth.point_W.allFinite();
  if (est.contact && est.has(EstimateFlag::kLineOfAction)) {
    if (point_known)
      m_.line.add(point_line_distance(truth.point_W, est.line_point_W, est.line_direction_W));
  } else {
    ++m_.line_not_estimated;
  }
  if (point_known && est.contact && est.has(EstimateFlag::kSurfacePoint))
    m_.surface.add((est.point_W - truth.point_W).norm());
  if (est.contact && est.has(EstimateFlag::kForce) && std::isfinite(est.sigma_force)) {
    const double error = (est.force_W - truth.force_W).norm();
    const bool flagged = est.has(EstimateFlag::kUncertain);
    ++m_.sigma_samples;
    if (error <= 2.0 * est.sigma_force) ++m_.force_within_two_sigma;
    if (flagged) ++m_.uncertain;
    if (error > kLargeForceError * truth.force_W.norm() && !flagged)
      ++m_.large_force_error_unflagged;
  }
}

Metrics MetricsAccumulator::result() const {
  Metrics m = m_;
  if (moment_estimated_) {
    m.moment.count += moment_undetected_.count;
    m.moment.sum_sq += moment_undetected_.sum_sq;
    m.moment.max = std::max(m.moment.max, moment_undetected_.max);
  }
  return m;
}

}  // namespace extwrench::sim
