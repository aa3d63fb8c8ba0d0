// What a job checks of a log's header before reading its rows, shared by the replay
// (`extwrench estimate`) and the calibration (`extwrench calibrate`): the same log gets the same
// answer from both.
#pragma once

#include <string>
#include <vector>

#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/io/log.hpp"

namespace extwrench::detail {

/// Joint columns beyond the robot's n (q8, dq8, tau8, true_tau_ext8 on a 7-joint robot): an
/// error naming them (a log of another robot, or with a gripper's joints) unless `ignore`.
void check_joint_columns(const LogReader& reader, int n, bool ignore);

/// The columns the configured base sensor needs (fs_*, and ms_* for an F/T sensor): an error
/// naming the missing ones.
void check_sensor_columns(const LogReader& reader, SensorType sensor);

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
  void add(const Sample& sample) noexcept;
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

}  // namespace extwrench::detail
