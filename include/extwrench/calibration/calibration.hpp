// Calibration from a contact-free log (docs/calibration.md): per-joint friction (viscous +
// Coulomb with a smooth sign, observer/friction.hpp) and a constant torque offset, the base
// sensor's bias, the residual noise left over and detection thresholds for a stated false-alarm
// rate.
//
// Formulation (no q̈ needed): the momentum residual (eq. 4) is linear in the friction torque
// the observer subtracts. With the friction model τ_f(q̇) = Σ_k θ_k φ_k(q̇) and the observer run
// once without friction (residual r⁰), the residual with friction θ is exactly
//
//   r(θ) = r⁰ + Σ_k θ_k z_k,    z_k = the observer's filter applied to φ_k(q̇(t))
//
// (same exact first-order discretisation and trapezoidal rule as the observer), so the θ that
// makes the residual of a contact-free log smallest is a linear least-squares problem per joint,
// solved with a small ridge term on column-scaled regressors. The Coulomb smoothing velocity
// (and the sigmoid's shift, or the Dahl sign's presliding displacement) enters non-linearly: it
// is chosen per joint on a grid, or set.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/estimation/estimator_options.hpp"
#include "extwrench/observer/friction.hpp"

namespace extwrench {

/// The form of the joint thresholds (docs/calibration.md#thresholds-that-follow-the-motion).
enum class ThresholdModel {
  kAuto,      ///< a + b|q̇| where its mean over the motion is ≥ 5 % below the constant one
  kConstant,  ///< τ_thr = a
  kSpeed,     ///< τ_thr = a + b|q̇| on every joint
};

/// The sign of a calibration by name, as the command line and Python take it: "tanh",
/// "sigmoid" or "dahl"; nullopt for anything else.
[[nodiscard]] std::optional<SmoothSign> calibration_sign(std::string_view name);

/// The threshold form by name: "auto", "constant" or "speed"; nullopt for anything else.
[[nodiscard]] std::optional<ThresholdModel> threshold_model(std::string_view name);

struct CalibrationOptions {
  ThresholdModel thresholds = ThresholdModel::kAuto;
  SmoothSign sign = SmoothSign::kTanh;  ///< tanh, sigmoid or dahl (saturation also accepted)
  double smoothing_velocity = 0.0;      ///< > 0: v_s fixed [rad/s] (dahl: δ [rad]); 0: per joint
  double false_alarms_per_hour = 1.0;   ///< target rate of the thresholds, all joints together
  double threshold_margin = 1.1;        ///< thresholds ≥ margin × the largest fitted residual
  double regularisation = 1e-9;         ///< ridge λ relative to the scaled normal matrix
  double settle_time = -1.0;            ///< skipped after the start [s]; < 0: 5 / min K
  double contact_sigma = 12.0;          ///< a contact: residual above this many robust σ ...
  double contact_min_duration = 0.05;   ///< ... for at least this long [s]
  double max_contact_fraction = 0.2;    ///< more suspected contact than this: refused
  /// Also fit, per joint, a correction δI of the inertia along the joint in the observer's
  /// momentum (p = B(q) q̇ + δI q̇, EstimatorOptions::inertia_correction) with the friction, kept
  /// where it lowers the residual's sum of squares by ≥ 10 %, also beyond the velocity's noise
  /// and a gravity error (docs/calibration.md#inertia-correction). Opt-in: it lowers thresholds
  /// set from a short log.
  bool inertia_correction = false;
  bool payload = false;  ///< identify a payload on the last link (needs a base F/T sensor)
  /// The samples' true_tau_ext is an external torque known during the recording (a force plate
  /// or a known load: J_vᵀF), subtracted from the residual before the fit, so a log in contact
  /// calibrates too (docs/calibration.md#calibrating-in-contact). No base sensor: its bias
  /// would absorb the contact.
  bool known_external_torque = false;
};

/// A payload identified on a link (docs/calibration.md#payload): mass and CoM from the base
/// wrench, added to the estimator's model (and to a configured payload on the same link).
struct PayloadReport {
  bool identified = false;
  int body = -1;                         ///< the link carrying it (the last one)
  double mass = 0.0;                     ///< [kg]
  Vector3 com = Vector3::Zero();         ///< in that link's frame [m]
  Vector6 rms_before = Vector6::Zero();  ///< sensor prediction error per axis, bias only
  Vector6 rms_after = Vector6::Zero();   ///< ... with the payload [N | N m]
  double condition = 0.0;                ///< of the column-scaled regression
  int samples = 0;
};

/// Fit quality of one joint, over the samples used.
struct JointFitReport {
  double rms_before = 0.0;  ///< residual RMS with the configured friction [N m]
  double rms_after = 0.0;   ///< residual RMS after calibration [N m]
  double max_before = 0.0;  ///< max |residual| with the configured friction
  double max_after = 0.0;   ///< max |residual| after calibration
  /// When max_after occurred (the log's t) [s]: the moment that sets a largest_residual
  /// threshold, e.g. a start from rest, which a later stretch of the same motion may not repeat.
  double max_after_t = 0.0;
  double variance_explained = 0.0;  ///< 1 − var(after) / var(before)
  double noise_std = 0.0;           ///< standard deviation of the residual after calibration
  double crossing_rate = 0.0;       ///< up-crossings of its mean per second (Rice's ν₀) [1/s]
  double condition = 0.0;           ///< of the column-scaled regression
  double threshold = 0.0;           ///< τ_min for the false-alarm rate [N m]
  bool threshold_from_max = false;  ///< threshold set by margin × max_after (heavier tails)
  // The noise's growth with speed: std(r | q̇) ≈ noise_at_rest + noise_per_speed |q̇| (a line
  // through E|r| against |q̇|), and the thresholds a + b|q̇| for the same false-alarm rate.
  double noise_at_rest = 0.0;         ///< [N m]
  double noise_per_speed = 0.0;       ///< [N m s/rad]
  double threshold_constant = 0.0;    ///< the constant threshold for the rate [N m]
  double threshold_at_rest = 0.0;     ///< a of a + b|q̇| [N m]
  double threshold_per_speed = 0.0;   ///< b of a + b|q̇| [N m s/rad]
  double mean_threshold_speed = 0.0;  ///< mean of a + b|q̇| over the samples used [N m]
  bool speed_dependent = false;       ///< the threshold chosen is a + b|q̇| (b > 0)
  double inertia_correction = 0.0;    ///< δI fitted [kg m² | kg] (0: none)
  double inertia_gain = 0.0;          ///< share of the friction fit's sum of squares it removed
};

/// A recognisable error of the model named by the model check (docs/calibration.md#model-check).
struct ModelPattern {
  /// base_force_offset | gravity | coulomb | presliding | inertia | inertia_or_gravity |
  /// sensor_pose | high_frequency | velocity_noise
  std::string kind;
  int joint = 0;       ///< 1-based joint, 0 for the base sensor
  double share = 0.0;  ///< R² of the pattern's regression, or offset / spread
  std::string message;
};

/// How well the model predicts free motion before calibration, and what its errors look like.
struct ModelCheck {
  VectorX joint_rms;                      ///< residual RMS per joint, model as configured [N m]
  Vector6 sensor_rms = Vector6::Zero();   ///< reading − prediction per axis (S), bias included
  Vector6 sensor_mean = Vector6::Zero();  ///< its mean per axis
  std::vector<ModelPattern> patterns;
};

/// A time window whose residual does not look like free motion.
struct SuspectWindow {
  double t_begin = 0.0, t_end = 0.0;  ///< [s]
  int joint = 0;                      ///< 1-based joint with the largest excess
  double peak = 0.0;                  ///< largest |residual| in the window [N m]
};

struct Calibration {
  JointFriction friction;  ///< viscous, Coulomb, offset, v_s (and φ) per joint
  VectorX tau_threshold;   ///< detection τ_min per joint (n) [N m]: a of τ_thr = a + b|q̇|
  VectorX tau_per_speed;   ///< b per joint (n) [N m s/rad]; empty or zero: constant thresholds
  VectorX observer_gain;   ///< K the residual and thresholds were computed with (n)
  /// The residual filter's cutoff per joint they were computed with (n) [Hz] (0: none;
  /// residual_filter.hpp).
  VectorX residual_cutoff;
  /// The velocity filter's cutoff per joint (n) [Hz] (0: none): the fit's observer formed its
  /// momentum from the log's q̇ through it, as the estimator's does. Empty when loaded from a
  /// file written before it existed (none).
  VectorX velocity_cutoff;
  /// δI per joint (n) [kg m² | kg]: the observer's momentum correction fitted with the friction
  /// (0 where not kept; EstimatorOptions::inertia_correction). Empty when loaded from a file
  /// written before it existed.
  VectorX inertia_correction;
  SensorType sensor_type = SensorType::kNone;
  Vector6 sensor_bias_S = Vector6::Zero();  ///< [f; n] in S (moment zero for a force sensor)
  Vector3 force_noise_W = Vector3::Zero();  ///< std of F̂_ext per world axis after the bias [N]
  /// std of the residual per joint after calibration (n; = joints[i].noise_std) [N m]; what a
  /// configuration including the file takes as the residual's noise (uncertainty.hpp). Empty
  /// when loaded from a file without fit.joints.
  VectorX residual_noise;
  double force_threshold = 0.0;  ///< F_min after calibration [N] (0: no sensor)
  double false_alarms_per_hour = 1.0;
  PayloadReport payload;  ///< with CalibrationOptions::payload
  ModelCheck model_check;
  std::vector<JointFitReport> joints;
  int samples_used = 0;
  double t_begin = 0.0, t_end = 0.0;  ///< time span of the samples given [s]
  std::string source;                 ///< the log it came from (set by the caller;
                                      ///< load_calibration: the file's calibration.source)
  std::vector<SuspectWindow> suspect_windows;
  std::vector<std::string> warnings;
};

/// Calibrates from `samples` (contact-free free motion, or with known_external_torque a motion
/// whose external torque is known; q̇ filled, t increasing) with the model
/// and the estimator options (observer gain, sensor type and pose, payload). Throws
/// extwrench::Error on a non-finite sample (its index), fewer samples than parameters, a joint
/// whose friction the motion does not excite (naming the parameter and the motion that would),
/// or a log whose residual looks like contact over more than max_contact_fraction (naming the
/// time windows); shorter suspect windows are excluded, listed and warned about.
[[nodiscard]] Calibration calibrate(const Model& model, const EstimatorOptions& options,
                                    const std::vector<Sample>& samples,
                                    const CalibrationOptions& calibration_options = {});

/// Adds the calibration's identified payload (if any) to options.payload: set when there is
/// none, summed with a configured payload on the same body. False, options unchanged, when the
/// configured payload is on another body (the caller says so, in its own terms).
[[nodiscard]] bool add_identified_payload(const Calibration& calibration,
                                          EstimatorOptions& options);

/// The options with the calibration applied: friction, residual_cutoff, inertia_correction,
/// detection.tau_min and tau_per_speed, (with a sensor) f_min and the sensor bias, and an
/// identified payload (added to a configured one on the same body; throws extwrench::Error when
/// the configured one is on another body).
[[nodiscard]] EstimatorOptions apply_calibration(EstimatorOptions options,
                                                 const Calibration& calibration);

}  // namespace extwrench
