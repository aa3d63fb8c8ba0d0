// Models of the robot's measurements: base force/torque sensor, joint encoders, velocities.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "extwrench/core/sample.hpp"
#include "extwrench/core/types.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/observer/friction.hpp"
#include "extwrench/sim/random.hpp"

namespace extwrench::sim {

/// The base sensor (docs/method.md#newton-euler-and-the-base-sensor): what the robot discharges
/// onto it, in its own frame, moment about its origin, plus a constant bias and white Gaussian
/// noise per axis.
struct BaseSensorModel {
  SensorType type = SensorType::kForceTorque;
  Pose X_WS;                         ///< pose of the sensor frame in the robot's root frame W
  Vector6 bias_S = Vector6::Zero();  ///< [N; N m] added to every reading
  Vector3 force_noise_S = Vector3::Zero();   ///< standard deviation per axis [N]
  Vector3 moment_noise_S = Vector3::Zero();  ///< standard deviation per axis [N m]

  /// Ideal reading + bias + noise. Noise is drawn for all six axes every call (whatever the
  /// type), so the stream does not depend on the sensor type.
  [[nodiscard]] Vector6 measure(const Vector6& ideal, Rng& rng) const noexcept;
  /// A sample's reading from the ideal one: measure(), then what the type reports (has_force,
  /// has_moment; the axes it does not have are 0). Every simulator fills its samples so.
  void write_reading(const Vector6& ideal, Rng& rng, Sample& out) const noexcept;
};

/// Joint encoders and the velocity the robot reports.
struct EncoderModel {
  double resolution = 0.0;       ///< quantization step [rad | m]; 0: exact positions
  bool differentiate = false;    ///< q̇ by backward difference of the measured q (else exact)
  double velocity_cutoff = 0.0;  ///< first-order low-pass on the difference [Hz]; 0: none

  /// Quantized position: resolution · round(q / resolution).
  [[nodiscard]] double quantize(double q) const noexcept;
};

/// The joint torques the robot logs beside the command τ that the link dynamics see: the
/// friction its drives overcome, τ_f of the true motion (the estimator's friction model,
/// observer/friction.hpp: D q̇ + F_c s + o, any sign, the Dahl sign's state advanced by the true
/// Δq from zero; a drive that delivers it on top of the command, as a joint-torque or current
/// measurement then contains it), and white Gaussian noise: τ_log = τ + τ_f + σ n. What a
/// calibration identifies (docs/calibration.md).
struct JointTorqueModel {
  std::optional<JointFriction> friction;  ///< none when empty
  /// σ_i [N m | N] ≥ 0 of white noise per joint (a real arm's wrist is quieter than its
  /// shoulder: calibrate's noise per joint); empty: none.
  VectorX noise;

  /// Friction or noise set.
  [[nodiscard]] bool active() const noexcept {
    return friction.has_value() || (noise.size() > 0 && (noise.array() > 0.0).any());
  }
  /// Throws extwrench::Error naming `where` on a friction validate_friction refuses for n
  /// joints, or a noise of another size than n (or empty), or a σ_i < 0.
  void validate(int n, const std::string& where) const;
};

/// Measured joint state from the true one, sample after sample.
class JointSensor {
 public:
  JointSensor(EncoderModel model, int n);
  /// True q, q̇ at time t → measured q, q̇ (written into q_out, dq_out, size n). The first
  /// call, and every call when the velocity is not differentiated, reports q̇ exactly.
  void measure(double t, const VectorX& q, const VectorX& dq, VectorX& q_out,
               VectorX& dq_out) noexcept;

 private:
  EncoderModel model_;
  VectorX last_q_, last_dq_;
  double last_t_ = 0.0;
  bool first_ = true;
};

}  // namespace extwrench::sim
