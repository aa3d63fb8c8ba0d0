// Contact detection and isolation (SPEC §2): thresholds with hysteresis and a minimum duration.
//
//  - joint i is "over" when |τ̂_ext,i| > τ_min,i and stays over until |τ̂_ext,i| < ratio · τ_min,i;
//    the base force likewise with ‖F̂_ext‖ and F_min (release level = release_ratio × on level);
//  - the raw detection is "any joint or the base force over"; a contact is declared once the raw
//    detection has held for min_duration seconds and released once it has been off for
//    min_duration seconds (debouncing both edges);
//  - link = the largest joint index over threshold (Remark 1: a wrench on link l only moves
//    τ_ext,1..l); a base-sensor detection with no joint over threshold is link 0.
#pragma once

#include "extwrench/core/types.hpp"

namespace extwrench {

struct DetectionOptions {
  VectorX tau_min = VectorX::Constant(1, 1.0);  ///< τ_min [N m | N]: size 1 (all joints) or n
  double f_min = 5.0;                           ///< F_min on ‖F̂_ext‖ from the base sensor [N]
  double release_ratio = 0.5;                   ///< off level = ratio × on level, in (0, 1]
  double min_duration = 0.005;                  ///< [s] ≥ 0, for both onset and release
};

struct DetectionResult {
  bool contact = false;  ///< declared contact
  bool pending =
      false;         ///< raw detection on, contact not (yet) declared, or raw off while declared
  bool raw = false;  ///< some joint or the base force is over its threshold now
  bool base_only = false;  ///< raw detection by the base force only
  int link = -1;           ///< isolated link while `contact` (0 = link 0), −1 otherwise
};

class ContactDetector {
 public:
  ContactDetector() = default;
  /// Throws extwrench::Error on sizes other than 1 or n, or values out of range.
  ContactDetector(const DetectionOptions& options, int n);

  void reset() noexcept;
  /// τ̂_ext (n) and ‖F̂_ext‖ (NaN when there is no usable base force) at time t. No allocation.
  const DetectionResult& update(double t, const Eigen::Ref<const VectorX>& tau_ext,
                                double base_force_norm) noexcept;
  [[nodiscard]] const DetectionResult& result() const noexcept { return result_; }
  [[nodiscard]] const VectorX& tau_min() const noexcept { return tau_min_; }
  [[nodiscard]] const DetectionOptions& options() const noexcept { return options_; }

 private:
  DetectionOptions options_;
  VectorX tau_min_;  ///< (n)
  Eigen::Matrix<bool, Eigen::Dynamic, 1> joint_over_;
  bool base_over_ = false;
  bool declared_ = false;
  bool have_edge_ = false;  ///< edge_time_ is valid
  double edge_time_ = 0.0;  ///< when the raw detection last changed against `declared_`
  int last_link_ = -1;
  DetectionResult result_;
};

}  // namespace extwrench
