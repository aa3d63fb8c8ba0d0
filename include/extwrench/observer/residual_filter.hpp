// An optional low-pass of the momentum residual (docs/estimator.md#residual-filter).
//
// Why: r = K [m − m(0) − ∫ …] contains K·B(q)·δq̇ for a velocity error δq̇ *unfiltered*
// (the first-order law filters τ_ext, not the momentum's own noise). On a real arm whose q̇ is
// differentiated from encoders, this puts broadband noise on the proximal joints, where B is
// largest: on the Franka Panda log at K = 50, 80 % of joints 1-4's residual power is above
// 15 Hz. Two critically damped first-order sections at `cutoff` Hz remove it, at the cost of a
// delay of about 2 / (2π cutoff) (16 ms at 20 Hz).
//
// Each section is integrated exactly for an input held over the step (zero-order hold, the
// same law as the observer's), with the actual Δt of the time stamps:
//
//   y_{k+1} = y_k + (1 − e^{−ω Δt}) (x_{k+1} − y_k),   ω = 2π cutoff,
//
// so DC passes with gain 1 and a constant input is reproduced exactly. The same step serves the
// estimator (ResidualFilter) and the calibration (residual_filter_step on the residual and on
// each regressor: the filter is linear), so the thresholds are computed on the signal the
// detector compares with them, to rounding.
#pragma once

#include <cmath>
#include <numbers>

#include "extwrench/core/types.hpp"

namespace extwrench {

/// Weight (1 − e^{−ω Δt}) of one step of a section at `cutoff` Hz over `dt` seconds.
[[nodiscard]] inline double residual_filter_weight(double cutoff, double dt) noexcept {
  return -std::expm1(-2.0 * std::numbers::pi * cutoff * dt);
}

/// One step of both sections for one channel: s1, s2 the section states, x the new input.
/// Returns the filtered value (the new s2).
inline double residual_filter_step(double weight, double x, double& s1, double& s2) noexcept {
  s1 += weight * (x - s1);
  s2 += weight * (s1 - s2);
  return s2;
}

/// The second-order low-pass over n channels, each with its own cutoff (0: that channel passes
/// unchanged). State only; no allocation after construction.
class ResidualFilter {
 public:
  ResidualFilter() = default;
  /// cutoff [Hz] per channel: size 1 (every channel) or n, entries ≥ 0 (0: none). Entries that
  /// are not finite and > 0 count as 0; options are checked where they are read (validate).
  ResidualFilter(const VectorX& cutoff, int n)
      : cutoff_(per_joint(cutoff, n)),
        weight_(VectorX::Zero(n)),
        s1_(VectorX::Zero(n)),
        s2_(VectorX::Zero(n)) {
    for (Eigen::Index i = 0; i < cutoff_.size(); ++i)
      if (!(cutoff_[i] > 0.0 && std::isfinite(cutoff_[i]))) cutoff_[i] = 0.0;
    enabled_ = cutoff_.size() == n && (cutoff_.array() > 0.0).any();
  }

  [[nodiscard]] bool enabled() const noexcept { return enabled_; }
  /// The cutoff per channel [Hz] (n; 0: none).
  [[nodiscard]] const VectorX& cutoff() const noexcept { return cutoff_; }

  /// Both sections at `value` (n): a start at rest on that value.
  void reset(const Eigen::Ref<const VectorX>& value) noexcept {
    s1_ = value;
    s2_ = value;
  }
  void reset() noexcept {
    s1_.setZero();
    s2_.setZero();
  }

  /// Replaces x (n) by its filtered value after a step of dt ≥ 0 seconds. No-op when disabled.
  /// The weights are recomputed only when dt changes (a fixed rate computes them once).
  void apply(double dt, Eigen::Ref<VectorX> x) noexcept {
    if (!enabled_) return;
    if (dt != weight_dt_) {
      for (Eigen::Index i = 0; i < x.size(); ++i)
        weight_[i] = cutoff_[i] > 0.0 ? residual_filter_weight(cutoff_[i], dt) : 0.0;
      weight_dt_ = dt;
    }
    for (Eigen::Index i = 0; i < x.size(); ++i)
      if (cutoff_[i] > 0.0) x[i] = residual_filter_step(weight_[i], x[i], s1_[i], s2_[i]);
  }

 private:
  VectorX cutoff_, weight_, s1_, s2_;
  double weight_dt_ = -1.0;  ///< the dt weight_ was computed for
  bool enabled_ = false;
};

}  // namespace extwrench
