// Known joint friction, part of the model the observer and the estimators use.
//
//   τ_f,i(q̇_i) = D_i q̇_i + F_c,i · sat(q̇_i / v_s),   sat(x) = clamp(x, −1, 1)
//
// τ_f is the torque friction *opposes* the motion with: the joint equation reads
// B q̈ + C q̇ + g + τ_f = τ + τ_ext, so the estimators subtract τ_f from the commanded τ.
// Coulomb friction is smoothed linearly over |q̇| < v_s (sign(0) = 0): at rest the
// static friction is unknown and modelled as zero, which keeps τ_f continuous in q̇.
#pragma once

#include "extwrench/model/model.hpp"

namespace extwrench {

struct JointFriction {
  VectorX viscous;                   ///< D_i ≥ 0 (n) [N m s/rad | N s/m]
  VectorX coulomb;                   ///< F_c,i ≥ 0 (n) [N m | N]
  double smoothing_velocity = 1e-3;  ///< v_s > 0 [rad/s | m/s]

  /// No friction on n joints.
  [[nodiscard]] static JointFriction none(int n);
  /// From Joint::damping and Joint::friction (URDF <dynamics>).
  [[nodiscard]] static JointFriction from_model(const Model& model);
  [[nodiscard]] bool is_zero() const noexcept;
};

/// τ_f(q̇) into `out` (n). No allocation.
void friction_torque(const JointFriction& friction, const Eigen::Ref<const VectorX>& dq,
                     Eigen::Ref<VectorX> out) noexcept;

/// Throws extwrench::Error (prefixed by `where`) unless sizes are n, entries finite and ≥ 0,
/// and v_s > 0.
void validate_friction(const JointFriction& friction, int n, const std::string& where);

}  // namespace extwrench
