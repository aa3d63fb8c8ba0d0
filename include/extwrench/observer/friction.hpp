// Known joint friction, part of the model the observer and the estimators use.
//
//   τ_f,i(q̇_i) = D_i q̇_i + F_c,i · s(q̇_i) + o_i
//
// with the smooth sign s one of (docs/calibration.md)
//   saturation  s = clamp(q̇ / v_s, −1, 1)                       (the URDF default)
//   tanh        s = tanh(q̇ / v_s,i)
//   sigmoid     s = tanh((q̇ + φ_i) / v_s,i) − tanh(φ_i / v_s,i)
// The sigmoid is the family Gaz et al. (2019) identified on the Panda,
// A/(1 + e^{−α(q̇+φ)}) − A/(1 + e^{−αφ}), rewritten with A = 2 F_c and α = 2 / v_s. o_i is a
// constant torque offset (sensor offset, unmodelled load), identified by `extwrench calibrate`.
//
// τ_f is the torque friction *opposes* the motion with: the joint equation reads
// B q̈ + C q̇ + g + τ_f = τ + τ_ext, so the estimators subtract τ_f from the commanded τ.
// Coulomb friction is smoothed linearly over |q̇| < v_s (sign(0) = 0): at rest the
// static friction is unknown and modelled as zero, which keeps τ_f continuous in q̇.
#pragma once

#include <cstdint>
#include <string_view>

#include "extwrench/model/model.hpp"

namespace extwrench {

/// The smooth sign of the Coulomb term.
enum class SmoothSign : std::uint8_t { kSaturation, kTanh, kSigmoid };

[[nodiscard]] std::string_view to_string(SmoothSign s) noexcept;

struct JointFriction {
  VectorX viscous;                   ///< D_i ≥ 0 (n) [N m s/rad | N s/m]
  VectorX coulomb;                   ///< F_c,i ≥ 0 (n) [N m | N]
  double smoothing_velocity = 1e-3;  ///< v_s > 0 [rad/s | m/s], when joint_smoothing is empty
  SmoothSign sign = SmoothSign::kSaturation;
  VectorX offset;           ///< o_i (size 0 = none, or n) [N m | N]
  VectorX joint_smoothing;  ///< v_s,i > 0 per joint (size 0 = smoothing_velocity, or n)
  VectorX velocity_shift;   ///< φ_i of the sigmoid (size 0 = zero, or n) [rad/s | m/s]

  /// No friction on n joints.
  [[nodiscard]] static JointFriction none(int n);
  /// From Joint::damping and Joint::friction (URDF <dynamics>).
  [[nodiscard]] static JointFriction from_model(const Model& model);
  [[nodiscard]] bool is_zero() const noexcept;
  /// v_s of joint i.
  [[nodiscard]] double smoothing(Eigen::Index i) const noexcept {
    return joint_smoothing.size() > 0 ? joint_smoothing[i] : smoothing_velocity;
  }
};

/// s(q̇) of joint i (the smooth sign above).
[[nodiscard]] double smooth_sign(const JointFriction& friction, Eigen::Index i, double dq) noexcept;
/// s(q̇) for a sign model, smoothing velocity v_s > 0 and shift φ (calibration's regressors).
[[nodiscard]] double smooth_sign(SmoothSign sign, double dq, double smoothing,
                                 double shift) noexcept;

/// τ_f(q̇) into `out` (n). No allocation.
void friction_torque(const JointFriction& friction, const Eigen::Ref<const VectorX>& dq,
                     Eigen::Ref<VectorX> out) noexcept;

/// Throws extwrench::Error (prefixed by `where`) unless sizes are n (0 allowed for offset,
/// joint_smoothing, velocity_shift), D and F_c finite and ≥ 0, o and φ finite, and v_s > 0.
void validate_friction(const JointFriction& friction, int n, const std::string& where);

}  // namespace extwrench
