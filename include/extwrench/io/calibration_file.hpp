// The calibration file CALIB.yaml written by `extwrench calibrate` and included by an estimator
// configuration (`calibration: CALIB.yaml`); docs/calibration.md describes every key.
//
//   calibration: {version: 1, source: FREE.csv, t_begin: 0, t_end: 12.6, ...}
//   observer: {gain: [...]}            # K the thresholds were computed with
//   friction: {sign: tanh, viscous: [...], coulomb: [...], offset: [...],
//              smoothing_velocity: [...]}      # (velocity_shift: [...] for the sigmoid)
//   detection: {tau_min: [...], tau_per_speed: [...], f_min: F}
//              # tau_per_speed (thresholds a + b|q̇|) only when some b > 0; f_min with a sensor
//   sensor: {type: ft, bias: [fx, fy, fz, mx, my, mz]}
//   fit: {...}      # report: per-joint RMS before/after, variance explained, condition, ...
//   holdout: {...}  # report of --holdout
//   warnings: [...]
//
// Reading takes observer, friction, detection and sensor; the report keys are not interpreted.
#pragma once

#include <filesystem>
#include <string>

#include "extwrench/calibration/calibration.hpp"
#include "extwrench/calibration/holdout.hpp"

namespace extwrench {

/// CALIB.yaml text; `holdout` may be null.
[[nodiscard]] std::string calibration_to_yaml(const Calibration& calibration,
                                              const HoldoutReport* holdout);

/// Reads a calibration for a robot with n joints. Throws extwrench::Error "file:line: key: what".
[[nodiscard]] Calibration load_calibration(const std::filesystem::path& path, int n);

}  // namespace extwrench
