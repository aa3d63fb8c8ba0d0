// Honest validation of a calibration (docs/calibration.md): the estimator run over a whole
// contact-free log, with and without the calibration, judged only on the samples after the fit
// window. Reports false alarms, the smallest constant thresholds that would have stayed quiet
// without calibration, and the smallest force each link would need to be detected.
#pragma once

#include <vector>

#include "extwrench/calibration/calibration.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

struct HoldoutReport {
  int samples = 0;        ///< samples judged (from `first` on)
  double duration = 0.0;  ///< their time span [s]
  int false_alarms = 0;   ///< samples with a declared contact, calibrated estimator
  int raw_alarms = 0;     ///< samples with some threshold exceeded, calibrated estimator
  int uncalibrated_false_alarms = 0;  ///< the same with the options as configured
  /// The same with the calibration but its constant thresholds (JointFitReport::
  /// threshold_constant) where it chose a + b|q̇|; equal to false_alarms when all are constant.
  int constant_threshold_false_alarms = 0;
  VectorX calibrated_threshold;           ///< τ_min of the calibration (n): a of a + b|q̇|
  VectorX calibrated_per_speed;           ///< b of a + b|q̇| (n; zero: constant)
  VectorX calibrated_constant_threshold;  ///< the calibration's constant thresholds (n)
  VectorX best_constant_threshold;        ///< max |r_i| without calibration on these samples (n)
  VectorX calibrated_max_residual;        ///< max |r_i| with calibration on these samples (n)
  double lever = 0.3;                     ///< [m] from the link origin, ⊥ its joint axis
  /// Per link 1..n (index 0 unused): the median over the samples of the smallest force at the
  /// lever point that crosses a threshold (best direction) [N], with the calibrated thresholds
  /// (a + b|q̇| at each sample's q̇) and with best_constant_threshold.
  std::vector<double> min_force_calibrated, min_force_constant;
  /// The same with the calibration's constant thresholds (calibrated_constant_threshold).
  std::vector<double> min_force_calibrated_constant;
  /// The same with calibrated_max_residual as thresholds: both sides at the smallest constant
  /// thresholds quiet on these samples, with and without calibration.
  std::vector<double> min_force_calibrated_quiet;
  /// When the log carries true_tau_ext (simulation, or a force plate: J_vᵀF): RMS of
  /// r_i − τ_ext,i over the judged samples without and with the calibration (n); else empty.
  VectorX tracking_rms_uncalibrated, tracking_rms_calibrated;
};

/// Runs both estimators over all `samples` (the fit window too, so that the residuals are in
/// their steady state) and judges samples[first..]. `options` as configured; `calibration` from
/// calibrate() on samples[..first).
[[nodiscard]] HoldoutReport validate_holdout(const Model& model, const EstimatorOptions& options,
                                             const Calibration& calibration,
                                             const std::vector<Sample>& samples, std::size_t first,
                                             double lever = 0.3);

/// The smallest force at point p_W on body `link` (best direction) that makes some joint's
/// |J_v(p)ᵀ F| exceed its threshold: 1 / max_i (‖J_v,i‖ / τ_min,i). `data` holds the poses.
[[nodiscard]] double smallest_detectable_force(const Model& model, const Data& data, int link,
                                               const Vector3& p_W, const VectorX& tau_min);

}  // namespace extwrench
