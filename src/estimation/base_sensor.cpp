#include "extwrench/estimation/base_sensor.hpp"

namespace extwrench {

std::string_view to_string(SensorType s) noexcept {
  switch (s) {
    case SensorType::kNone:
      return "none";
    case SensorType::kForce:
      return "force";
    case SensorType::kForceTorque:
      return "ft";
  }
  return "unknown";
}

Pose default_sensor_pose(const Model& model) {
  const auto frame = model.find_frame("sensor");
  if (!frame) return Pose::identity();
  const Frame& f = model.frames[static_cast<std::size_t>(*frame)];
  return f.body == 0 ? f.placement : Pose::identity();  // link 0 is W: the placement is X_WS
}

}  // namespace extwrench
