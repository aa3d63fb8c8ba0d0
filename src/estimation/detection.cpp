#include "extwrench/estimation/detection.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"

namespace extwrench {
namespace {
// Time stamps are sums of floating steps: a duration reached up to this slack counts as reached.
constexpr double kTimeSlack = 1e-9;  // [s]

// The factor of a threshold term that follows the motion (tau_per_speed, inertial_margin): none,
// one for all joints or one per joint, each finite and >= 0.
void check_optional_slopes(const VectorX& values, const std::string& key, const char* unit, int n) {
  if (values.size() != 0 && values.size() != 1 && values.size() != n) {
    throw Error(key + ": expected 1 or " + std::to_string(n) + " values, got " +
                std::to_string(values.size()));
  }
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]) || values[i] < 0.0) {
      throw Error(key + "[" + std::to_string(i) + "]: expected a finite value >= 0 " + unit);
    }
  }
}
}  // namespace

void validate(const DetectionOptions& options, int n) {
  const VectorX& t = options.tau_min;
  if (t.size() != 1 && t.size() != n) {
    throw Error("detection.tau_min: expected 1 or " + std::to_string(n) + " values, got " +
                std::to_string(t.size()));
  }
  for (int i = 0; i < n; ++i) {
    const double v = t.size() == 1 ? t[0] : t[i];
    if (!std::isfinite(v) || !(v > 0.0)) {
      throw Error("detection.tau_min[" + std::to_string(i) + "]: expected a finite value > 0");
    }
  }
  check_optional_slopes(options.tau_per_speed, "detection.tau_per_speed", "[N m s/rad]", n);
  check_optional_slopes(options.inertial_margin, "detection.inertial_margin",
                        "(a fraction of the joint's dynamic torque)", n);
  if (!std::isfinite(options.f_min) || !(options.f_min > 0.0)) {
    throw Error("detection.f_min: expected a finite value > 0");
  }
  if (!(options.release_ratio > 0.0 && options.release_ratio <= 1.0)) {
    throw Error("detection.release_ratio: expected a value in (0, 1]");
  }
  if (!std::isfinite(options.min_duration) || options.min_duration < 0.0) {
    throw Error("detection.min_duration: expected a finite value >= 0 [s]");
  }
  if (!std::isfinite(options.sensor_release_duration) || options.sensor_release_duration < 0.0) {
    throw Error("detection.sensor_release_duration: expected a finite value >= 0 [s]");
  }
}

ContactDetector::ContactDetector(const DetectionOptions& options, int n, double release_settle_time)
    : options_(options), release_settle_time_(release_settle_time) {
  validate(options, n);
  const VectorX& t = options.tau_min;
  tau_min_ = per_joint(t, n);
  const VectorX& b = options.tau_per_speed;
  tau_speed_ = b.size() == 0 ? VectorX::Zero(n) : per_joint(b, n);
  speed_dependent_ = (tau_speed_.array() > 0.0).any();
  const VectorX& c = options.inertial_margin;
  margin_ = c.size() == 0 ? VectorX::Zero(n) : per_joint(c, n);
  inertia_dependent_ = (margin_.array() > 0.0).any();
  threshold_ = tau_min_;
  joint_over_.setConstant(n, false);
}

void ContactDetector::set_motion(const Eigen::Ref<const VectorX>& dq) noexcept {
  if (!speed_dependent_) return;
  threshold_.array() = tau_min_.array() + tau_speed_.array() * dq.array().abs();
}

void ContactDetector::set_motion(const Eigen::Ref<const VectorX>& dq,
                                 const Eigen::Ref<const VectorX>& dynamic_torque) noexcept {
  if (!inertia_dependent_) {
    set_motion(dq);
    return;
  }
  threshold_.array() = tau_min_.array() + tau_speed_.array() * dq.array().abs() +
                       margin_.array() * dynamic_torque.array().abs();
}

void ContactDetector::reset() noexcept {
  joint_over_.setConstant(false);
  base_over_ = false;
  declared_ = false;
  have_edge_ = false;
  last_link_ = -1;
  rearm_ = false;
  release_time_ = 0.0;
  release_level_ = 0.0;
  sensor_release_disproved_ = false;
  threshold_ = tau_min_;
  result_ = DetectionResult{};
}

const DetectionResult& ContactDetector::update(double t, const Eigen::Ref<const VectorX>& tau_ext,
                                               double base_force_norm, double release_force_norm,
                                               double measured_release_force_norm) noexcept {
  const double ratio = options_.release_ratio;
  int link = -1;
  for (Eigen::Index i = 0; i < threshold_.size(); ++i) {
    // Hysteresis: once over, a joint stays over until it falls below ratio × τ_thr.
    const double level = joint_over_[i] ? ratio * threshold_[i] : threshold_[i];
    joint_over_[i] = std::abs(tau_ext[i]) > level;
    if (joint_over_[i]) link = static_cast<int>(i) + 1;  // largest joint index over threshold
  }
  if (std::isfinite(base_force_norm)) {
    const double level = base_over_ ? ratio * options_.f_min : options_.f_min;
    base_over_ = base_force_norm > level;
  } else {
    base_over_ = false;
  }
  const bool base_only = base_over_ && link < 0;
  if (base_only) link = 0;  // a contact no joint feels is on link 0 (Sec. II-B)
  bool raw = link >= 0;
  const bool over = raw;
  if (!over) sensor_release_disproved_ = false;
  // The sensor says the force is gone: release without waiting for the residual's decay.
  bool sensor_off = false;
  if (declared_ && !sensor_release_disproved_ && std::isfinite(release_force_norm) &&
      !(release_force_norm > ratio * options_.f_min)) {
    raw = false;
    sensor_off = std::isfinite(measured_release_force_norm) &&
                 !(measured_release_force_norm > ratio * options_.f_min);
  }
  if (rearm_) {  // after a sensor release, a new onset needs every threshold to have dropped
    if (!over) {
      rearm_ = false;
    } else if (t - release_time_ > release_settle_time_ &&
               level(tau_ext, base_force_norm) > 0.5 * release_level_) {
      // The residual has had time to decay and has not: the force is still there.
      rearm_ = false;
      sensor_release_disproved_ = true;
    } else {
      raw = false;
    }
  }

  // Debounce both edges: the raw state must hold for min_duration before it is declared; a
  // release the measured-q̈ force confirms (now) for sensor_release_duration.
  if (raw != declared_) {
    if (!have_edge_) {
      have_edge_ = true;
      edge_time_ = t;
    }
    const double hold = sensor_off ? options_.sensor_release_duration : options_.min_duration;
    if (t - edge_time_ >= hold - kTimeSlack) {
      declared_ = raw;
      have_edge_ = false;
      if (!raw && over) {
        rearm_ = true;
        release_time_ = t;
        release_level_ = level(tau_ext, base_force_norm);
      }
    }
  } else {
    have_edge_ = false;
  }
  if (raw) last_link_ = link;

  result_.contact = declared_;
  result_.pending = raw != declared_;
  result_.raw = raw;
  result_.base_only = base_only;
  result_.link = declared_ ? last_link_ : -1;
  return result_;
}

double ContactDetector::level(const Eigen::Ref<const VectorX>& tau_ext,
                              double base_force_norm) const noexcept {
  double out = std::isfinite(base_force_norm) ? base_force_norm / options_.f_min : 0.0;
  for (Eigen::Index i = 0; i < threshold_.size(); ++i)
    out = std::max(out, std::abs(tau_ext[i]) / threshold_[i]);
  return out;
}

}  // namespace extwrench
