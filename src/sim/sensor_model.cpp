#include "extwrench/sim/sensor_model.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "extwrench/core/error.hpp"

namespace extwrench::sim {

Vector6 BaseSensorModel::measure(const Vector6& ideal, Rng& rng) const noexcept {
  Vector6 out = ideal + bias_S;
  for (int k = 0; k < 3; ++k) out[k] += force_noise_S[k] * rng.normal();
  for (int k = 0; k < 3; ++k) out[3 + k] += moment_noise_S[k] * rng.normal();
  return out;
}

double EncoderModel::quantize(double q) const noexcept {
  if (resolution <= 0.0) return q;
  return resolution * std::round(q / resolution);
}

JointSensor::JointSensor(EncoderModel model, int n)
    : model_(model), last_q_(VectorX::Zero(n)), last_dq_(VectorX::Zero(n)) {}

void BaseSensorModel::write_reading(const Vector6& ideal, Rng& rng, Sample& out) const noexcept {
  out.reading_S = measure(ideal, rng);
  out.has_force = type != SensorType::kNone;
  out.has_moment = type == SensorType::kForceTorque;
  if (!out.has_force) out.reading_S.setZero();
  if (!out.has_moment) out.reading_S.tail<3>().setZero();
}

void JointSensor::measure(double t, const VectorX& q, const VectorX& dq, VectorX& q_out,
                          VectorX& dq_out) noexcept {
  for (Eigen::Index i = 0; i < q.size(); ++i) q_out[i] = model_.quantize(q[i]);
  if (!model_.differentiate || first_) {
    dq_out = dq;
  } else {
    const double dt = t - last_t_;
    // Backward difference, then an optional first-order low-pass (exact discretization).
    const double alpha = model_.velocity_cutoff > 0.0
                             ? 1.0 - std::exp(-2.0 * std::numbers::pi * model_.velocity_cutoff * dt)
                             : 1.0;
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      const double raw = (q_out[i] - last_q_[i]) / dt;
      dq_out[i] = last_dq_[i] + alpha * (raw - last_dq_[i]);
    }
  }
  first_ = false;
  last_t_ = t;
  last_q_ = q_out;
  last_dq_ = dq_out;
}

void JointTorqueModel::validate(int n, const std::string& where) const {
  if (friction) validate_friction(*friction, n, where);
  if (noise.size() != 0 && noise.size() != n) {
    throw Error(where + ".noise: expected " + std::to_string(n) + " values (one per joint), got " +
                std::to_string(noise.size()));
  }
  for (Eigen::Index i = 0; i < noise.size(); ++i) {
    if (!(noise[i] >= 0.0) || !std::isfinite(noise[i]))
      throw Error(where + ".noise[" + std::to_string(i) + "]: expected a finite value >= 0");
  }
}

}  // namespace extwrench::sim
