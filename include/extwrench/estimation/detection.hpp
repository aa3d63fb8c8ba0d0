// Contact detection and isolation (Sec. II-B, docs/method.md#detection-and-isolation): thresholds
// with hysteresis and a minimum duration.
//
//  - joint i is "over" when |τ̂_ext,i| > τ_thr,i and stays over until |τ̂_ext,i| < ratio · τ_thr,i,
//    with τ_thr,i = τ_min,i + b_i |q̇_i| + c_i |τ_dyn,i| (b = tau_per_speed, c =
//    inertial_margin, docs/calibration.md; 0 by default: a constant threshold);
//    the base force likewise with ‖F̂_ext‖ and F_min (release level = release_ratio × on level);
//  - the raw detection is "any joint or the base force over"; a contact is declared once the raw
//    detection has held for min_duration seconds and released once it has been off for
//    min_duration seconds (debouncing both edges), or for sensor_release_duration when the base
//    sensor's instantaneous force says the contact has ended;
//  - link = the largest joint index over threshold (Remark 1: a wrench on link l only moves
//    τ_ext,1..l); a base-sensor detection with no joint over threshold is link 0.
//
// Isolation (isolate): the link the wrench cases work on, from the detection and the contact
// assumption (a known point names its link whatever the detection says).
#pragma once

#include <cstdint>
#include <limits>

#include "extwrench/core/types.hpp"
#include "extwrench/estimation/contact_estimate.hpp"

namespace extwrench {

struct DetectionOptions {
  VectorX tau_min = VectorX::Constant(1, 1.0);  ///< τ_min [N m | N]: size 1 (all joints) or n
  /// b ≥ 0 of τ_thr,i = τ_min,i + b_i |q̇_i| [N m s/rad]: size 0 (none), 1 (all joints) or n.
  VectorX tau_per_speed;
  /// c ≥ 0 adding c_i |τ_dyn,i| to τ_thr,i: τ_dyn = τ − τ_f − g(q) + τ̂_ext = B q̈ + C q̇ is the
  /// torque that accelerates the arm, c the model's relative inertia error, whose residual grows
  /// with it (docs/calibration.md, "The inertial margin"). Size 0 (none), 1 or n.
  VectorX inertial_margin;
  double f_min = 5.0;           ///< F_min on ‖F̂_ext‖ from the base sensor [N]
  double release_ratio = 0.5;   ///< off level = ratio × on level, in (0, 1]
  double min_duration = 0.005;  ///< [s] ≥ 0, for both onset and release
  /// [s] ≥ 0: how long the base sensor's instantaneous force (the release force) must stay below
  /// its release level to end a contact. Shorter than min_duration because that force needs no
  /// residual to decay and no threshold to rise over noise: 1 ms = two samples at 1 kHz below
  /// the level (docs/estimator.md#release-from-the-sensor).
  double sensor_release_duration = 0.001;
};

struct DetectionResult {
  bool contact = false;  ///< declared contact
  bool pending =
      false;         ///< raw detection on, contact not (yet) declared, or raw off while declared
  bool raw = false;  ///< some joint or the base force is over its threshold now
  bool base_only = false;  ///< raw detection by the base force only
  int link = -1;           ///< isolated link while `contact` (0 = link 0), −1 otherwise
};

/// Throws extwrench::Error on sizes other than 1 or n, or values out of range.
void validate(const DetectionOptions& options, int n);

class ContactDetector {
 public:
  ContactDetector() = default;
  /// Throws extwrench::Error on sizes other than 1 or n, or values out of range (validate).
  /// release_settle_time [s]: how long τ̂_ext may take to decay after the force ends (the
  /// estimator passes 5 time constants of its residual).
  ContactDetector(const DetectionOptions& options, int n,
                  double release_settle_time = std::numeric_limits<double>::infinity());

  void reset() noexcept;
  /// The thresholds for the current joint velocities: τ_thr = τ_min + b ∘ |q̇| (no-op without
  /// tau_per_speed). Call before update() with the sample's q̇ (finite, size n). No allocation.
  void set_motion(const Eigen::Ref<const VectorX>& dq) noexcept;
  /// The same plus c ∘ |τ_dyn| (inertial_margin; τ_dyn finite, size n). No allocation.
  void set_motion(const Eigen::Ref<const VectorX>& dq,
                  const Eigen::Ref<const VectorX>& dynamic_torque) noexcept;
  /// τ̂_ext (n) and ‖F̂_ext‖ (NaN when there is no usable base force) at time t. No allocation.
  /// release_force_norm: the sensor's instantaneous force (docs/estimator.md#release-from-the-
  /// sensor), NaN when unknown. When finite, a declared contact is released once it falls below
  /// release_ratio × f_min, however slowly τ̂_ext decays; a new onset then waits until every
  /// joint and the base force have fallen below their release levels (one rising edge each).
  /// If `release_settle_time` after the release the signals have not even halved (relative to
  /// their thresholds; a force that ended leaves a residual decaying to < 1 % by then), the
  /// force is still there and the release was wrong (the sensor's instantaneous force assumes
  /// the isolated link, which may be the wrong one): the contact is declared again and the
  /// sensor may not release it until every threshold has dropped. The release holds for
  /// min_duration, or for sensor_release_duration while measured_release_force_norm (the force
  /// with q̈ measured, which assumes no contact point; NaN when unknown) is below the level too.
  const DetectionResult& update(double t, const Eigen::Ref<const VectorX>& tau_ext,
                                double base_force_norm, double release_force_norm = kNoReleaseForce,
                                double measured_release_force_norm = kNoReleaseForce) noexcept;
  static constexpr double kNoReleaseForce = std::numeric_limits<double>::quiet_NaN();
  [[nodiscard]] const DetectionResult& result() const noexcept { return result_; }
  /// The joint thresholds in force: τ_min + b ∘ |q̇| (+ c ∘ |τ_dyn|) at the last set_motion
  /// (τ_min when constant).
  [[nodiscard]] const VectorX& thresholds() const noexcept { return threshold_; }
  /// The same as thresholds() (its name from before the thresholds followed |q̇|; kept for
  /// compatibility: it returns τ_min + b ∘ |q̇|, not options().tau_min).
  [[nodiscard]] const VectorX& tau_min() const noexcept { return threshold_; }
  /// Whether the thresholds follow |q̇| (tau_per_speed given and not all zero).
  [[nodiscard]] bool speed_dependent() const noexcept { return speed_dependent_; }
  /// Whether they follow |τ_dyn| (inertial_margin given and not all zero).
  [[nodiscard]] bool inertia_dependent() const noexcept { return inertia_dependent_; }
  [[nodiscard]] const DetectionOptions& options() const noexcept { return options_; }

 private:
  DetectionOptions options_;
  VectorX tau_min_;    ///< a: constant part (n)
  VectorX tau_speed_;  ///< b: per |q̇| (n; zero when constant)
  VectorX margin_;     ///< c: per |τ_dyn| (n; zero when none)
  VectorX threshold_;  ///< τ_thr in force (n)
  bool speed_dependent_ = false;
  bool inertia_dependent_ = false;
  Eigen::Matrix<bool, Eigen::Dynamic, 1> joint_over_;
  bool base_over_ = false;
  bool declared_ = false;
  bool have_edge_ = false;  ///< edge_time_ is valid
  double edge_time_ = 0.0;  ///< when the raw detection last changed against `declared_`
  int last_link_ = -1;
  bool rearm_ = false;                ///< released by the sensor while thresholds were still over
  double release_time_ = 0.0;         ///< when the sensor last released [s]
  double release_level_ = 0.0;        ///< the signals' level (level()) at that release
  double release_settle_time_ = 0.0;  ///< see the constructor [s]
  bool sensor_release_disproved_ = false;  ///< no sensor release until every threshold drops
  DetectionResult result_;

  /// max(|τ̂_ext,i| / τ_thr,i, ‖F̂‖ / F_min): how far over its threshold the strongest signal is.
  [[nodiscard]] double level(const Eigen::Ref<const VectorX>& tau_ext,
                             double base_force_norm) const noexcept;
};

/// The EstimateFlag bits of a detection result: contact, pending, base only.
[[nodiscard]] inline std::uint32_t detection_flags(const DetectionResult& det) noexcept {
  std::uint32_t flags = 0;
  if (det.contact) flags |= EstimateFlag::kContact;
  if (det.pending) flags |= EstimateFlag::kPending;
  if (det.contact && det.base_only) flags |= EstimateFlag::kBaseOnly;
  return flags;
}

/// Isolation rule. In: the detection, the contact assumption and, for a known point, its link.
/// Out: the link the wrench cases work on (−1: none); kLinkMismatch added to `flags` when a
/// declared contact is isolated on another link than the known point's.
[[nodiscard]] inline int isolate(const DetectionResult& det, ContactModel model, int known_link,
                                 std::uint32_t& flags) noexcept {
  if (model != ContactModel::kKnownPoint) return det.contact ? det.link : -1;
  if (det.contact && det.link != known_link) flags |= EstimateFlag::kLinkMismatch;
  return known_link;
}

}  // namespace extwrench
