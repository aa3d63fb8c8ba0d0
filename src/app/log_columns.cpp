#include "log_columns.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench::detail {

namespace {

// "q8", "dq8", "tau8", "true_tau_ext8" with 8 > n: a log of another robot, or of this one with
// a gripper joint; either way the user should say so.
bool beyond_joints(const std::string& column, int n) {
  for (const char* prefix : {"true_tau_ext", "tau", "dq", "q"}) {
    const std::string p = prefix;
    if (column.size() <= p.size() || column.compare(0, p.size(), p) != 0) continue;
    const std::string digits = column.substr(p.size());
    if (digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos)
      return false;
    return std::stoi(digits) > n;
  }
  return false;
}

}  // namespace

void check_joint_columns(const LogReader& reader, int n, bool ignore) {
  if (ignore) return;
  std::string list;
  int count = 0;
  for (const std::string& c : reader.ignored_columns()) {
    if (!beyond_joints(c, n)) continue;
    if (++count <= 8) list += (list.empty() ? "" : ", ") + c;
  }
  if (count == 0) return;
  if (count > 8) list += " and " + std::to_string(count - 8) + " more";
  throw Error(reader.name() + ":1: columns " + list + " are beyond the robot's " +
              std::to_string(n) +
              " joints: is this the log of another robot (or of extra joints such as a "
              "gripper's)? Pass --ignore-extra-joints to ignore them on purpose");
}

void check_sensor_columns(const LogReader& reader, SensorType sensor) {
  const LogLayout& layout = reader.layout();
  if (sensor == SensorType::kForceTorque && !(layout.force && layout.moment)) {
    throw Error(reader.name() + ":1: the configuration's sensor.type is 'ft' but the log has no " +
                (layout.force ? "ms_x, ms_y, ms_z" : "fs_x..fs_z, ms_x..ms_z") + " columns");
  }
  if (sensor == SensorType::kForce && !layout.force) {
    throw Error(reader.name() +
                ":1: the configuration's sensor.type is 'force' but the log has no fs_x, fs_y, "
                "fs_z columns");
  }
}

JointRangeCheck::JointRangeCheck(const Model& model, Margin margin) : model_(&model) {
  const int n = model.nq();
  for (int i = 1; i <= n; ++i) {
    const Joint& j = model.joints[static_cast<std::size_t>(i)];
    const double range = j.upper - j.lower;
    // No limits (continuous), or none worth the name (lower = upper = 0: a URDF's default, an
    // exporter's placeholder): nothing to check against.
    const bool checked = std::isfinite(range) && range > 0.0;
    const double widen = margin == Margin::kLog ? std::max(0.1 * range, 0.1) : 0.0;
    lower_.push_back(checked ? j.lower - widen : -std::numeric_limits<double>::infinity());
    upper_.push_back(checked ? j.upper + widen : std::numeric_limits<double>::infinity());
  }
  excursions_.resize(lower_.size());
}

void JointRangeCheck::add(const Sample& sample) noexcept {
  ++rows_;
  if (static_cast<std::size_t>(sample.q.size()) != lower_.size()) return;
  for (std::size_t i = 0; i < lower_.size(); ++i) {
    const double q = sample.q[static_cast<Eigen::Index>(i)];
    const double beyond = q < lower_[i] ? lower_[i] - q : q > upper_[i] ? q - upper_[i] : 0.0;
    if (!(beyond > 0.0)) continue;
    Excursion& e = excursions_[i];
    ++e.rows;
    if (beyond > e.beyond) e = {e.rows, beyond, q, sample.t};
  }
}

bool JointRangeCheck::mostly_outside() const noexcept {
  return std::any_of(excursions_.begin(), excursions_.end(),
                     [&](const Excursion& e) { return 2 * e.rows > rows_; });
}

std::string JointRangeCheck::note() const {
  const auto most =
      std::max_element(excursions_.begin(), excursions_.end(),
                       [](const Excursion& a, const Excursion& b) { return a.rows < b.rows; });
  if (most == excursions_.end() || most->rows == 0) return {};
  const auto worst = static_cast<std::size_t>(most - excursions_.begin());
  const auto joints = std::count_if(excursions_.begin(), excursions_.end(),
                                    [](const Excursion& e) { return e.rows > 0; });
  const Joint& j = model_->joints[worst + 1];
  char shown[32];
  std::snprintf(shown, sizeof shown, "%.4g", most->q);
  return "q" + std::to_string(worst + 1) + " (joint '" + j.name + "') lies outside its limits [" +
         format_number(j.lower) + ", " + format_number(j.upper) +
         "] (by more than a tenth of the range) on " + std::to_string(most->rows) + " of " +
         std::to_string(rows_) + " rows (up to " + std::string(shown) + ")" +
         (joints > 1 ? ", and " + std::to_string(joints - 1) + " more joint" +
                           (joints > 2 ? "s" : "") + " too"
                     : std::string()) +
         (mostly_outside()
              ? ": are the positions in degrees, or of another robot? The model takes radians "
                "(and metres), in its joints' order"
              : ": an encoder's wrap or a glitch in those rows, or limits in the model that "
                "the robot exceeds? The estimates there use the positions as they are");
}

}  // namespace extwrench::detail
