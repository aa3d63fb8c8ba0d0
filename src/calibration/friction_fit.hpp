// Calibration internals: the per-joint friction least squares on the momentum residual
// (calibration.hpp explains the formulation).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "extwrench/calibration/calibration.hpp"

namespace extwrench::calibration_detail {

/// The smallest torque [N m] a calibration message is about: a model-check pattern that explains
/// less, or a friction coefficient fitted below zero on a residual smaller than this, is not
/// said. An ideal simulated log leaves ~1e-5 N m of integration error that follows q, q̇ and q̈
/// as closely as a real error would, and no joint torque sensor resolves a milli-newton-metre.
inline constexpr double kResolvableTorque = 1e-3;

/// One joint's series over the log: q̇_k, the residual r⁰_k without friction, and the filter
/// coefficient α_k = e^{−K Δt_k} of the step ending at sample k (α_0 unused). With a residual
/// filter on the joint (observer.residual_cutoff), its weight per step (residual_filter.hpp;
/// empty: none), and r⁰ is then the filtered residual: the fit minimises what the detector sees.
/// dt_k = t_k − t_{k−1} (dt_0 unused; empty: no inertia correction fitted); gravity: g_i(q_k),
/// and payload_gravity: the gravity torque of a unit mass at the last link's origin and of unit
/// first moments along its x, y, z (empty: not known); q: the joint's position (with gravity);
/// axis_along_gravity: the joint's axis stayed parallel to gravity over the log (a vertical
/// first axis), so no mass distribution gives it a gravity torque.
struct JointSeries {
  std::vector<double> q, dq, r0, alpha, dt, filter_weight, gravity;
  /// (B(q_k) q̇_k)_i: the momentum the observer forms, of the measured q̇ or of the velocity
  /// filter's; momentum_dq: that q̇_i where it is the velocity filter's (empty: dq), the q̇ the
  /// inertia correction's δI q̇ is added to; momentum_fast (required by fit_joint with
  /// inertia_correction): the part above ~1/kFastWindow of the observer's answer to the momentum
  /// (fast_part of filter_rate(momentum)), where a noisy measured velocity enters the residual
  /// as K B(q) δq̇ (model check, and a nuisance column of the inertia fit).
  std::vector<double> momentum, momentum_dq, momentum_fast;
  std::array<std::vector<double>, 4> payload_gravity;
  bool axis_along_gravity = false;
};

/// The same friction (D, F_c, o; no inertia correction) with the sign fitted and with the Dahl
/// sign instead, over the used samples: the residual's sum of squares and largest |r| of each,
/// and the Dahl fit's δ. Computed for a sign of q̇ (tanh, sigmoid): the model check names
/// `--sign dahl` where it lowers them (friction that lags the reversals). δ = 0: not computed.
struct DahlAlternative {
  double presliding = 0.0;  ///< δ of the best Dahl fit [rad]
  double rss = 0.0, peak = 0.0;
  double sign_rss = 0.0, sign_peak = 0.0;
};

/// The fitted friction of one joint and its fit statistics.
struct JointFrictionFit {
  /// smoothing: v_s [rad/s], or the Dahl sign's δ [rad].
  double viscous = 0.0, coulomb = 0.0, offset = 0.0, smoothing = 0.05, shift = 0.0;
  double inertia = 0.0;       ///< δI, the momentum's correction (0: not fitted) [kg m²]
  double inertia_gain = 0.0;  ///< share of friction's residual sum of squares it removed
  double condition = 1.0;
  std::vector<double> residual;  ///< r(θ) over the whole log
  std::vector<std::string> warnings;
  DahlAlternative dahl;
};

/// The window [s] of fast_part that separates the velocity's noise (above ~20 Hz) from the
/// motion, friction and gravity errors (below).
inline constexpr double kFastWindow = 1.0 / 20.0;

/// x minus its centred mean over the samples within ±window/2 of each time stamp: the part of x
/// above ~1/window (the mean's first zero), on time stamps that need not be uniform.
[[nodiscard]] std::vector<double> fast_part(const std::vector<double>& x,
                                            const std::vector<Sample>& samples, double window);

/// The least-squares line y ≈ intercept + slope x over the samples with use[k] != 0 (centred
/// sums). r2 = 0 and slope = 0 when fewer than 3 samples or x or y is constant.
struct LineFit {
  double count = 0.0, mean_x = 0.0, mean_y = 0.0;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;  ///< centred sums of squares and products
  double slope = 0.0, intercept = 0.0, r2 = 0.0;
};
[[nodiscard]] LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y,
                               const std::vector<char>& use);

/// The observer's filter of a regressor: z_k = α_k z_{k−1} + (1 − α_k) ½ (φ_{k−1} + φ_k), z_0 = 0;
/// then, when `residual_filter_weight` is not empty, the residual filter's two sections with
/// those weights per step (from rest at 0, as the estimator's after a reset).
void filter_regressor(const std::vector<double>& phi, const std::vector<double>& alpha,
                      std::vector<double>& z,
                      const std::vector<double>& residual_filter_weight = {});

/// The observer's filter of a rate of change: z_k = α_k z_{k−1} + (1 − α_k)(x_k − x_{k−1})/Δt_k,
/// z_0 = 0 (a term δ x added to the momentum), then the residual filter as filter_regressor.
void filter_rate(const std::vector<double>& x, const std::vector<double>& alpha,
                 const std::vector<double>& dt, std::vector<double>& z,
                 const std::vector<double>& residual_filter_weight = {});

/// The residual filter over a series in place, with its weights per step (none when empty).
void apply_residual_filter(const std::vector<double>& weight, std::vector<double>& x);

/// The residual filter's weight per step at `cutoff` Hz over the samples' time stamps (the
/// weight of step k, from sample k − 1 to k, at k; 0 at k = 0).
[[nodiscard]] std::vector<double> residual_filter_weights(const std::vector<Sample>& samples,
                                                          double cutoff);

/// Whether an error of the joint's inertia and an error of its gravity torque give the same
/// residual in this motion: gravity can load the joint (its axis is not along gravity) and its
/// acceleration follows its position, |corr(q̈_i, q_i)| ≥ 0.95 over the used samples, as in a
/// motion of one sine per joint (q̈ = −ω² (q − q0)). A gravity error that changes with q_i (a
/// link's centre of mass off, not a multiple of the model's g_i) then looks like −δI q̈.
/// `acceleration`: q̈_i (central_acceleration); `correlation` gets corr(q̈_i, q_i).
[[nodiscard]] bool inertia_aliases_gravity(const JointSeries& s,
                                           const std::vector<double>& acceleration,
                                           const std::vector<char>& use, double& correlation);

/// q̈_k by central differences of q̇, (q̇_{k+1} − q̇_{k−1}) / (Δt_k + Δt_{k+1}); 0 at both ends.
[[nodiscard]] std::vector<double> central_acceleration(const JointSeries& s);

/// Throws extwrench::Error when joint `joint` (1-based) does not move enough, in both
/// directions, to identify its viscous and Coulomb friction over the samples in `use`.
void check_excitation(const JointSeries& s, const std::vector<char>& use, int joint,
                      double smoothing);

/// Fits D, F_c, o (and v_s, φ on a grid unless fixed) on the samples with use[k] != 0; with
/// options.inertia_correction also δI (p += δI q̇ of the momentum's q̇), kept where it lowers the
/// residual's sum of squares by ≥ 10 % beyond the velocity's noise (s.momentum_fast) and a
/// gravity error (g_i(q) and a last-link payload's gravity, when s.payload_gravity is known),
/// nuisance regressors of those tests only; the friction is then refitted with δI held, and δI
/// kept only where that residual is smaller than friction's alone.
[[nodiscard]] JointFrictionFit fit_joint(const JointSeries& s, const std::vector<char>& use,
                                         const CalibrationOptions& options, int joint);

/// A measured value in a message, to `digits` significant digits ("0.01", "23.371", "100",
/// "1.2e+08"): std::to_string's fixed six decimals read "0.010000 rad/s ... 100.000000 %".
[[nodiscard]] std::string number_text(double value, int digits = 4);

}  // namespace extwrench::calibration_detail
