// Joint positions against the model's limits, row by row: the one check of a log's positions,
// shared by `extwrench estimate`, `calibrate`, `simulate` and the Python estimate().
#pragma once

#include <string>
#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

/// Joint positions outside the model's limits (joints without limits, or with lower = upper, are
/// not checked), fed row by row. In a log (Margin::kLog) only far outside counts, by more than a
/// tenth of the range and at least 0.1 rad or m: on most rows, most often a log in degrees; on a
/// few, an encoder's wrap or a glitch (note()). A simulation's exact motion (Margin::kNone)
/// counts any excursion (excursions()).
class JointRangeCheck {
 public:
  enum class Margin { kLog, kNone };
  /// Per joint: the rows outside, and the furthest one: how far beyond, its q and its t.
  struct Excursion {
    long rows = 0;
    double beyond = 0.0, q = 0.0, t = 0.0;
  };

  explicit JointRangeCheck(const Model& model, Margin margin = Margin::kLog);
  /// One row: its time [s] and positions (a row of another size is counted, not checked).
  void add(double t, const Eigen::Ref<const VectorX>& q) noexcept;
  void add(const Sample& sample) noexcept { add(sample.t, sample.q); }
  [[nodiscard]] const std::vector<Excursion>& excursions() const noexcept { return excursions_; }
  /// The joint outside on the most rows, for a log; "" when none is.
  [[nodiscard]] std::string note() const;
  /// Some joint is outside on more than half of the rows (degrees, another robot's log).
  [[nodiscard]] bool mostly_outside() const noexcept;

 private:
  const Model* model_;
  std::vector<double> lower_, upper_;  // the limits checked (widened by the margin)
  std::vector<Excursion> excursions_;
  long rows_ = 0;
};

}  // namespace extwrench
