// The configuration enums of the estimators and their per-sample output (SensorType, the Table I
// columns, is in base_sensor.hpp).
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include "extwrench/core/status.hpp"
#include "extwrench/core/types.hpp"

namespace extwrench {

/// Contact assumption (Table I rows).
enum class ContactModel : std::uint8_t {
  kPureForce,   ///< unknown point, M_ext = 0: estimate F_ext and the line of action / point
  kKnownPoint,  ///< known point p on a given link: estimate F_ext and M_ext
};

/// Where q̈̂ and τ̂_ext come from (docs/method.md#acceleration-routes).
enum class AccelerationRoute : std::uint8_t {
  kResidual,  ///< (b) τ̂_ext = r, q̈̂ = B⁻¹(τ − τ_f + r − c)
  kDifferentiation,  ///< (a) q̈̂ = low-passed difference of q̇, τ̂_ext = RNEA(q, q̇, q̈̂) + τ_f − τ
};

[[nodiscard]] std::string_view to_string(ContactModel m) noexcept;
[[nodiscard]] std::string_view to_string(AccelerationRoute a) noexcept;

/// Bits of ContactEstimate::flags: what was estimated and how far to trust it.
struct EstimateFlag {
  static constexpr std::uint32_t kContact = 1u << 0;  ///< a contact is declared
  static constexpr std::uint32_t kPending = 1u << 1;  ///< over threshold, not yet for min_duration
  static constexpr std::uint32_t kForce = 1u << 2;    ///< force_W estimated
  static constexpr std::uint32_t kMoment = 1u << 3;   ///< moment_W estimated
  static constexpr std::uint32_t kLineOfAction =
      1u << 4;  ///< line_point_W / line_direction_W estimated
  static constexpr std::uint32_t kSurfacePoint =
      1u << 5;  ///< point_* is the line's entry on the link surface
  static constexpr std::uint32_t kSurfaceMissed =
      1u << 6;  ///< the line misses the link: point_* is the nearest surface point
  static constexpr std::uint32_t kKnownPoint = 1u
                                               << 7;  ///< point_* is the configured contact point
  static constexpr std::uint32_t kNoGeometry =
      1u << 8;  ///< the link has no collision shape: no surface point
  static constexpr std::uint32_t kIllConditioned =
      1u << 9;  ///< condition number over the limit: damped least squares
  static constexpr std::uint32_t kUnobservable =
      1u << 10;  ///< rank too low for moment / point (or force): not estimated
  static constexpr std::uint32_t kDisagreement =
      1u << 11;  ///< base wrench and residual inconsistent (e.g. two contacts)
  static constexpr std::uint32_t kBaseOnly = 1u << 12;  ///< seen by the base sensor only: link 0
  static constexpr std::uint32_t kTaring =
      1u << 13;  ///< sensor bias being estimated: sensor detection off
  static constexpr std::uint32_t kLinkMismatch =
      1u << 14;  ///< known-point link differs from the isolated link
  // Bits 20+: issue 9 (geometry-consistent isolation).
  static constexpr std::uint32_t kAmbiguous =
      1u << 20;  ///< another consistent candidate link is met as early along the line
  static constexpr std::uint32_t kResidualIsolation =
      1u << 21;  ///< geometry isolation could test no candidate: the paper's rule decided
  static constexpr std::uint32_t kPartial =
      1u << 22;  ///< rank deficient: the observable part only (observable_basis), rest zero
  static constexpr std::uint32_t kUncertain =
      1u << 23;  ///< the force's error bound exceeds the configured fraction (uncertainty.hpp)
};

/// Names of the set bits, separated by '|' ("contact|force|line|surface_point"); "free" for 0.
[[nodiscard]] std::string describe_flags(std::uint32_t flags);

/// One sample of the estimator (world frame W = the robot's root frame). A quantity that was not
/// estimated is NaN, and its flag is clear.
struct ContactEstimate {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  double t = kNaN;       ///< time stamp of the sample [s]
  bool contact = false;  ///< a contact is declared (detection with hysteresis and min_duration)
  int link =
      -1;  ///< contact link (body index, 0 = link 0; name: model.bodies[link].name); −1 if none
  Vector3 force_W = Vector3::Constant(kNaN);  ///< F̂_ext [N]
  Vector3 moment_W = Vector3::Constant(
      kNaN);  ///< M̂_ext [N m], pure moment besides the force at the point (known point)
  Vector3 point_W = Vector3::Constant(
      kNaN);  ///< contact point: surface point (pure force) or configured point [m]
  Vector3 point_L = Vector3::Constant(kNaN);  ///< the same in the link's frame [m]
  Vector3 line_point_W =
      Vector3::Constant(kNaN);  ///< p̂ of eq. (20): point of the line nearest O_l [m]
  Vector3 line_direction_W = Vector3::Constant(kNaN);  ///< unit F̂/‖F̂‖
  double surface_distance = kNaN;  ///< 0 when the line meets the link; > 0 when it misses [m]
  /// Geometry isolation: bit l set for every other link l consistent with the residual and the
  /// line of action (the chosen link excluded); 0 otherwise.
  std::uint64_t link_candidates = 0;
  /// kPartial: orthonormal basis (first observable_rank columns) of the observable subspace of
  /// the unknowns solved, as 6-vectors (F [N]; M̄ [N m] about O_l) in W; the reported force (and,
  /// for a known point, moment) is the minimum-norm solution within it.
  Eigen::Matrix<double, 6, 6> observable_basis_W = Eigen::Matrix<double, 6, 6>::Zero();
  int observable_rank = -1;  ///< dimension of that subspace; −1 when not partial
  // Uncertainty (docs/estimator.md#uncertainty): covariances in W and their 1-σ = √trace Σ, the
  // RMS norm of the error; NaN where the quantity is not estimated (or not propagated: partial).
  Matrix3 force_covariance_W = Matrix3::Constant(kNaN);   ///< Σ of force_W [N²]
  Matrix3 moment_covariance_W = Matrix3::Constant(kNaN);  ///< Σ of moment_W [N² m²]
  double sigma_force = kNaN;                              ///< [N]
  double sigma_moment = kNaN;                             ///< [N m]
  double sigma_line = kNaN;  ///< of the line's offset ⟂ to it at the reported point (p̂ if none) [m]
  double sigma_point = kNaN;  ///< of the surface point [m]
  VectorX residual;  ///< τ̂_ext (n) used for isolation: r, or RNEA − τ (differentiation route)
  /// Drift tracking (EstimatorOptions::drift): the joint torque offsets o_i in use (n) and the
  /// sensor bias [f; n] in S after this sample; size 0 / NaN without drift tracking.
  VectorX torque_offset;
  Vector6 sensor_bias_S = Vector6::Constant(kNaN);
  double condition_number =
      kNaN;       ///< σ_max/σ_min of the Jacobian inverted (cases D, E), SI units; NaN when none
  Status status;  ///< input errors; ok otherwise
  std::uint32_t flags = 0;  ///< EstimateFlag bits

  [[nodiscard]] bool has(std::uint32_t flag) const noexcept { return (flags & flag) != 0; }
};

}  // namespace extwrench
