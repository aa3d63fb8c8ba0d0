// Simulated free motion for the calibration tests: the project's simulator (no friction), then
// the joint torques the motors of a robot *with* friction and torque offsets would have
// measured for the same motion, τ_m = τ + D q̇ + F_c tanh(q̇ / v_s) + o + noise. The motion obeys
// B q̈ + C q̇ + g + τ_f = τ_m − o exactly, which is the robot the calibration assumes.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "extwrench/model/sample_models.hpp"
#include "extwrench/sim/controller.hpp"
#include "extwrench/sim/random.hpp"
#include "extwrench/sim/simulator.hpp"

namespace extwrench::test {

/// presliding (when not empty): a Dahl sign with these δ_i [rad] instead of tanh(q̇ / v_s).
struct TrueFriction {
  VectorX viscous, coulomb, offset, smoothing, presliding;
};

/// The Dahl state after a displacement, by 200 explicit Euler steps of dz/dq = (sign − z) / δ:
/// a numerical integration of the model's equation, independent of the library's closed form.
inline double dahl_euler(double z, double displacement, double presliding) {
  if (displacement == 0.0) return z;
  const double s = displacement > 0.0 ? 1.0 : -1.0;
  const double h = std::abs(displacement) / 200.0;
  for (int k = 0; k < 200; ++k) z += h * (s - z) / presliding;
  return z;
}

inline TrueFriction paper_arm_friction() {
  TrueFriction f;
  f.viscous.resize(7);
  f.coulomb.resize(7);
  f.offset.resize(7);
  f.viscous << 0.8, 1.0, 0.6, 0.7, 0.3, 0.25, 0.2;
  f.coulomb << 0.9, 1.2, 0.7, 0.8, 0.4, 0.3, 0.25;
  f.offset << 0.15, -0.2, 0.1, -0.05, 0.08, -0.12, 0.04;
  f.smoothing = VectorX::Constant(7, 0.03);
  return f;
}

inline sim::SinusoidalTrajectory free_motion(double phase_shift, double speed) {
  sim::SinusoidalTrajectory t;
  t.offset.resize(7);
  t.amplitude.resize(7);
  t.frequency.resize(7);
  t.phase.resize(7);
  t.offset << 0.0, 0.55, 0.0, -0.6, 0.0, 0.6, 0.0;
  t.amplitude << 0.8, 0.4, 0.6, 0.5, 0.8, 0.5, 1.0;
  t.frequency << 0.11, 0.13, 0.17, 0.19, 0.23, 0.29, 0.31;
  t.frequency *= speed;
  for (int i = 0; i < 7; ++i) t.phase[i] = phase_shift * (i + 1);
  return t;
}

/// A push of `newtons` tangential to link `link`'s joint axis (y of its frame) at 0.1 m along x,
/// held over [start, end] s.
inline sim::ForceProfile tangential_push(int link, double newtons, double start, double end) {
  sim::ForceProfile push;
  push.frame = "link" + std::to_string(link);
  push.axes = sim::ForceProfile::Axes::kFrame;
  push.point_F = Vector3(0.1, 0.0, 0.0);
  push.force = Vector3(0.0, newtons, 0.0);
  push.start = start;
  push.end = end;
  return push;
}

struct SimulatedLog {
  std::vector<Sample> samples;
};

/// `duration` s of `trajectory` on the paper arm with a base F/T sensor (bias, noise), joint
/// torque noise `tau_noise` [N m] and the true friction; `forces` pushes the robot;
/// `sensor_pose`: the sensor's true pose (the estimator may assume another);
/// `tau_noise_per_speed` [N m s/rad]: torque noise that grows with the speed, σ = tau_noise +
/// tau_noise_per_speed |q̇| (the Panda's measured τ and q̇ carry such noise).
inline std::vector<Sample> simulate_free_motion(
    const Model& model, const sim::SinusoidalTrajectory& trajectory, const TrueFriction& friction,
    double duration, const Vector6& sensor_bias, double tau_noise, std::uint64_t seed,
    std::vector<sim::ForceProfile> forces = {}, const Pose& sensor_pose = Pose(),
    double tau_noise_per_speed = 0.0) {
  const double omega = 10.0;
  sim::PidGains gains;
  gains.kp = VectorX::Constant(7, 3 * omega * omega);
  gains.kd = VectorX::Constant(7, 3 * omega);
  gains.ki = VectorX::Constant(7, omega * omega * omega);
  sim::ComputedTorqueController controller(model, trajectory, gains);
  sim::SimulationConfig config;
  config.duration = duration;
  config.sample_time = 1e-3;
  config.sensor.type = SensorType::kForceTorque;
  config.sensor.X_WS = sensor_pose;
  config.sensor.bias_S = sensor_bias;
  config.sensor.force_noise_S = Vector3::Constant(0.2);
  config.sensor.moment_noise_S = Vector3::Constant(0.02);
  config.noise_seed = seed;
  config.forces = std::move(forces);
  sim::Simulator simulator(model, controller, config);
  sim::Rng rng(seed + 1000);
  std::vector<Sample> samples;
  samples.reserve(static_cast<std::size_t>(simulator.num_samples()));
  Sample s;
  VectorX dahl = VectorX::Zero(7);  // the Dahl states, from rest
  while (simulator.next(s)) {
    for (int i = 0; i < 7; ++i) {
      const double dq = s.dq[i];
      double sign = 0.0;
      if (friction.presliding.size() > 0) {
        if (!samples.empty())
          dahl[i] = dahl_euler(dahl[i], s.q[i] - samples.back().q[i], friction.presliding[i]);
        sign = dahl[i];
      } else {
        sign = std::tanh(dq / friction.smoothing[i]);
      }
      s.tau[i] += friction.viscous[i] * dq + friction.coulomb[i] * sign + friction.offset[i] +
                  (tau_noise + tau_noise_per_speed * std::abs(dq)) * rng.normal();
    }
    samples.push_back(s);
  }
  return samples;
}

}  // namespace extwrench::test
