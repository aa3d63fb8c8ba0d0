#include "log_columns.hpp"

#include <string>

#include "extwrench/core/error.hpp"

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

}  // namespace extwrench::detail
