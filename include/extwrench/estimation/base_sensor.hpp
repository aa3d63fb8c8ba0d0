// The base force/torque sensor (Table I columns): its type, its default pose, the check of a
// reading, the tare, and the reading turned into the estimator's base quantities
//   F̂_ext = f_m − f̃_g                 (11)
//   n_m − ñ_g = M_ext + r_{s,p} × F_ext (13)   (F/T only)
// with (f̃_g, ñ_g) what the robot would discharge with this motion and no contact (the
// no-contact ground wrench of the RNEA pass), all in W, moments about the sensor origin O_s.
// docs/estimator.md describes the sensor frame S; X_WS is its pose in W (the root frame).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include "extwrench/core/input_checks.hpp"
#include "extwrench/core/status.hpp"
#include "extwrench/core/types.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

/// Base sensor (Table I columns).
enum class SensorType : std::uint8_t {
  kNone,         ///< no base sensor: joint torques only (case E)
  kForce,        ///< 3-axis force sensor (cases A, D)
  kForceTorque,  ///< 6-axis F/T sensor (cases A, B, C)
};

[[nodiscard]] std::string_view to_string(SensorType s) noexcept;

/// The entries of a reading [f; n] the sensor measures: 6 (F/T), 3 (force), 0 (none).
[[nodiscard]] constexpr int reading_size(SensorType type) noexcept {
  return type == SensorType::kForceTorque ? 6 : type == SensorType::kForce ? 3 : 0;
}

/// X_WS used when none is configured: the placement of the frame named "sensor" when it is on
/// link 0 (the root frame W), else the root link's origin, aligned with it (identity); a
/// "sensor" frame on a moving body is not a base sensor and is ignored here (the CLI rejects it).
[[nodiscard]] Pose default_sensor_pose(const Model& model);

/// ok when the measured entries of `reading_S` (reading_size(type)) are finite; else kNonFinite
/// on the base-wrench channel with the index of the first bad entry.
[[nodiscard]] inline Status check_reading(SensorType type, const Vector6& reading_S) noexcept {
  const int count = reading_size(type);
  for (int i = 0; i < count; ++i) {
    if (!usable_input(reading_S[i])) return {StatusCode::kNonFinite, Channel::kBaseWrench, i};
  }
  return Status::success();
}

/// Sensor bias estimation: bias = mean(reading − predicted reading) over the requested samples
/// after a request (robot free of contact).
struct SensorTare {
  Vector6 bias_S = Vector6::Zero();  ///< subtracted from every reading (sensor frame)
  Vector6 sum = Vector6::Zero();
  int count = 0;
  int target = 0;  ///< > count while taring

  void request(int samples) noexcept {
    target = samples > 0 ? samples : 0;
    count = 0;
    sum.setZero();
  }
  [[nodiscard]] bool active() const noexcept { return count < target; }
  /// One taring sample. In: the reading and the predicted no-contact reading, sensor frame.
  /// Out: bias_S once the last sample is in (moment entries zero for a force sensor). Returns
  /// true while still taring after this sample.
  bool add(SensorType type, const Vector6& reading_S, const Vector6& predicted_S) noexcept {
    sum += reading_S - predicted_S;
    if (++count == target) {
      bias_S = sum / target;
      if (type == SensorType::kForce) bias_S.tail<3>().setZero();
      target = 0;
      count = 0;
      return false;
    }
    return true;
  }
};

/// The base quantities of a sample, world frame, about O_s.
struct BaseWrench {
  Vector3 force_W;  ///< F̂_ext = f_m − f̃_g (11)
  Vector3 dn_W;     ///< n_m − ñ_g (13): F/T only, NaN otherwise
  bool taring = false;
};

/// Base-sensor reading stage. In: the sensor type (not kNone) and pose X_WS, the reading [f; n]
/// in S, the predicted no-contact reading (f̃_g, ñ_g) in W about O_s (sensor_reading_world).
/// Updates the tare; returns F̂_ext and n_m − ñ_g in W.
[[nodiscard]] inline BaseWrench base_wrench(SensorType type, const Pose& X_WS,
                                            const Vector6& reading_S, const Vector6& predicted_W,
                                            SensorTare& tare) noexcept {
  BaseWrench out;
  out.dn_W.setConstant(std::numeric_limits<double>::quiet_NaN());
  if (tare.active()) {
    Vector6 predicted_S;
    predicted_S.head<3>().noalias() = X_WS.rotation.transpose() * predicted_W.head<3>();
    predicted_S.tail<3>().noalias() = X_WS.rotation.transpose() * predicted_W.tail<3>();
    out.taring = tare.add(type, reading_S, predicted_S);
  }
  const Vector6 corrected_S = reading_S - tare.bias_S;
  // Readings rotated from the sensor frame into W (moments stay about O_s).
  out.force_W.noalias() = X_WS.rotation * corrected_S.head<3>();
  out.force_W -= predicted_W.head<3>();  // (11) F̂_ext = f_m − f̃_g
  if (type == SensorType::kForceTorque) {
    out.dn_W.noalias() = X_WS.rotation * corrected_S.tail<3>();
    out.dn_W -= predicted_W.tail<3>();  // n_m − ñ_g = M_ext + r_{s,p} × F_ext   (13)
  }
  return out;
}

}  // namespace extwrench
