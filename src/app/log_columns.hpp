// What a job checks of a log's header before reading its rows, shared by the replay
// (`extwrench estimate`) and the calibration (`extwrench calibrate`): the same log gets the same
// answer from both.
#pragma once

#include <string>

#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/io/log.hpp"

namespace extwrench::detail {

/// Joint columns beyond the robot's n (q8, dq8, tau8, true_tau_ext8 on a 7-joint robot): an
/// error naming them (a log of another robot, or with a gripper's joints) unless `ignore`.
void check_joint_columns(const LogReader& reader, int n, bool ignore);

/// The columns the configured base sensor needs (fs_*, and ms_* for an F/T sensor): an error
/// naming the missing ones.
void check_sensor_columns(const LogReader& reader, SensorType sensor);

}  // namespace extwrench::detail
