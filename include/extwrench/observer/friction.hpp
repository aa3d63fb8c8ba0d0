// Known joint friction, part of the model the observer and the estimators use.
//
//   τ_f,i(q̇_i) = D_i q̇_i + F_c,i · s(q̇_i) + o_i
//
// with the smooth sign s one of (docs/calibration.md)
//   saturation  s = clamp(q̇ / v_s, −1, 1)                       (the URDF default)
//   tanh        s = tanh(q̇ / v_s,i)
//   sigmoid     s = tanh((q̇ + φ_i) / v_s,i) − tanh(φ_i / v_s,i)
//   dahl        s = z_i, the Dahl model's state: dz/dq = (sign(q̇) − z) / δ_i
// The sigmoid is the family Gaz et al. (2019) identified on the Panda,
// A/(1 + e^{−α(q̇+φ)}) − A/(1 + e^{−αφ}), rewritten with A = 2 F_c and α = 2 / v_s. o_i is a
// constant torque offset (sensor offset, unmodelled load), identified by `extwrench calibrate`.
// The Dahl sign is not a function of q̇: after a reversal friction builds up over a presliding
// displacement δ_i (a harmonic drive's flexsplines and bearings deform before they slip), so it
// lags the velocity's sign as measured on a real Panda's wrist (docs/calibration.md). Its state
// z_i ∈ [−1, 1] follows the joint's displacement between samples, integrated exactly for a
// displacement linear between them: z ← s + (z − s) e^{−|Δq|/δ}, s = sign(Δq) (dahl_step).
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
enum class SmoothSign : std::uint8_t { kSaturation, kTanh, kSigmoid, kDahl };

[[nodiscard]] std::string_view to_string(SmoothSign s) noexcept;

struct JointFriction {
  VectorX viscous;                   ///< D_i ≥ 0 (n) [N m s/rad | N s/m]
  VectorX coulomb;                   ///< F_c,i ≥ 0 (n) [N m | N]
  double smoothing_velocity = 1e-3;  ///< v_s > 0 [rad/s | m/s], when joint_smoothing is empty
  SmoothSign sign = SmoothSign::kSaturation;
  VectorX offset;           ///< o_i (size 0 = none, or n) [N m | N]
  VectorX joint_smoothing;  ///< v_s,i > 0 per joint (size 0 = smoothing_velocity, or n)
  VectorX velocity_shift;   ///< φ_i of the sigmoid (size 0 = zero, or n) [rad/s | m/s]
  VectorX presliding;       ///< δ_i > 0 of the Dahl sign (n with kDahl, else 0) [rad | m]

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

/// s(q̇) of joint i (the smooth sign above; for the Dahl sign its steady state in a motion of
/// constant direction, sign(q̇)).
[[nodiscard]] double smooth_sign(const JointFriction& friction, Eigen::Index i, double dq) noexcept;
/// s(q̇) for a sign model, smoothing velocity v_s > 0 and shift φ (calibration's regressors;
/// kDahl: sign(q̇), its steady state).
[[nodiscard]] double smooth_sign(SmoothSign sign, double dq, double smoothing,
                                 double shift) noexcept;

/// The Dahl state after a displacement `displacement` from state z, presliding displacement
/// δ > 0: sign + (z − sign) e^{−|Δq|/δ} (z unchanged when Δq = 0).
[[nodiscard]] double dahl_step(double z, double displacement, double presliding) noexcept;

/// τ_f(q̇) into `out` (n); a Dahl sign at its steady state sign(q̇). No allocation.
void friction_torque(const JointFriction& friction, const Eigen::Ref<const VectorX>& dq,
                     Eigen::Ref<VectorX> out) noexcept;
/// τ_f into `out` (n) with the Dahl states `presliding_state` (n; read only with kDahl). No
/// allocation.
void friction_torque(const JointFriction& friction, const Eigen::Ref<const VectorX>& dq,
                     const Eigen::Ref<const VectorX>& presliding_state,
                     Eigen::Ref<VectorX> out) noexcept;

/// Throws extwrench::Error (prefixed by `where`) unless sizes are n (0 allowed for offset,
/// joint_smoothing, velocity_shift), D and F_c finite and ≥ 0, o and φ finite, v_s > 0, and
/// δ finite, > 0 and of size n exactly with the Dahl sign (0 otherwise).
void validate_friction(const JointFriction& friction, int n, const std::string& where);

}  // namespace extwrench
