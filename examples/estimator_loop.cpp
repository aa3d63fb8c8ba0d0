// The contact estimator in a 1 kHz loop on a simulated robot.
//
// The "robot" is the paper's arm (models/paper_arm.urdf) integrated with the core's forward
// dynamics (RK4, torque held over each 1 ms sample), tracking a sinusoid with computed torque +
// PD. At t = 1 s a 20 N force, constant in frame 6, pushes at a point of link 6 for 1.5 s. The
// estimator (base F/T sensor, unknown point, pure force) sees only q, q̇, τ and the sensor's
// reading, and prints what it finds every 100 ms.
//
//   example_estimator_loop [path/to/robot.urdf [K]]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/robot_loader.hpp"

using namespace extwrench;

namespace {

constexpr double kDt = 1e-3;  // 1 kHz
constexpr double kT_on = 1.0, kT_off = 2.5, kT_end = 3.0;

struct Truth {
  int link = 6;
  Vector3 point_L{0.0, 0.0, 0.1};   // the paper's point (SPEC §5)
  Vector3 force_L{20.0, 0.0, 0.0};  // constant in frame 6
  bool on = false;

  int wrench(const Data& d, ExternalWrench& w) const {
    if (!on) return 0;
    w = {link, d.X_WB[link].rotation * force_L, d.X_WB[link].act(point_L), Vector3::Zero()};
    return 1;
  }
};

/// q̈ of the simulated robot: B q̈ = τ + J_pᵀ W − c, with the wrench applied through RNEA.
VectorX acceleration(const Model& m, Data& d, const Truth& truth, const VectorX& q,
                     const VectorX& dq, const VectorX& tau) {
  forward_kinematics(m, d, q);
  ExternalWrench w;
  const int nw = truth.wrench(d, w);
  VectorX tau_ext = VectorX::Zero(m.nq());
  if (nw > 0) {
    const VectorX zero = VectorX::Zero(m.nq());
    tau_ext = rnea(m, d, q, dq, zero);  // copy: rnea returns a reference into d
    tau_ext -= rnea(m, d, q, dq, zero, std::span<const ExternalWrench>(&w, 1));
  }
  if (!forward_dynamics(m, d, q, dq, tau + tau_ext))
    throw std::runtime_error("mass matrix not positive definite");
  return d.ddq;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path =
      argc > 1 ? argv[1] : std::string(EXTWRENCH_MODELS_DIR) + "/paper_arm.urdf";
  const double gain = argc > 2 ? std::atof(argv[2]) : 100.0;
  const RobotDescription robot = load_robot(path);
  const Model& model = robot.model;
  const int n = model.nq();
  Data sim(model), ctrl(model);

  EstimatorOptions options;
  options.sensor.type = SensorType::kForceTorque;
  options.sensor.pose = frame_pose(model, sim, model.frame_index("sensor"));  // fixed on link 0
  options.contact.model = ContactModel::kPureForce;
  options.observer_gain = VectorX::Constant(1, gain);
  ContactEstimator estimator(model, robot.geometry, options);

  // Trajectory and controller.
  auto desired = [n](double t, VectorX& qd, VectorX& dqd, VectorX& ddqd) {
    qd.resize(n), dqd.resize(n), ddqd.resize(n);
    for (int i = 0; i < n; ++i) {
      const double w = 2 * std::numbers::pi * (0.2 + 0.05 * i), a = 0.5;
      const double q0 = (i == 1 || i == 3) ? 0.6 : 0.0;
      qd[i] = q0 + a * std::sin(w * t);
      dqd[i] = a * w * std::cos(w * t);
      ddqd[i] = -a * w * w * std::sin(w * t);
    }
  };
  auto controller = [&](double t, const VectorX& q, const VectorX& dq) {
    VectorX qd, dqd, ddqd;
    desired(t, qd, dqd, ddqd);
    return VectorX(rnea(model, ctrl, q, dq, ddqd + 100.0 * (qd - q) + 20.0 * (dqd - dq)));
  };

  Truth truth;
  VectorX q, dq, unused;
  desired(0.0, q, dq, unused);
  double t = 0.0;
  VectorX tau = controller(t, q, dq);
  if (!estimator.reset(t, q, dq, tau).ok()) return 1;

  std::printf("%6s %7s %5s %24s %26s %8s  %s\n", "t[s]", "contact", "link", "F_hat [N] (world)",
              "surface point [m] (world)", "|F-F_hat|", "flags");
  double worst_us = 0.0, total_us = 0.0;
  int updates = 0;
  for (int k = 1; t < kT_end - 1e-9; ++k) {
    // --- the simulated robot: one RK4 step with τ held ---
    const double h = kDt;
    const VectorX a1 = acceleration(model, sim, truth, q, dq, tau);
    const VectorX a2 = acceleration(model, sim, truth, q + 0.5 * h * dq, dq + 0.5 * h * a1, tau);
    const VectorX a3 =
        acceleration(model, sim, truth, q + 0.5 * h * (dq + 0.5 * h * a1), dq + 0.5 * h * a2, tau);
    const VectorX a4 =
        acceleration(model, sim, truth, q + h * (dq + 0.5 * h * a2), dq + h * a3, tau);
    q += h * dq + h * h / 6 * (a1 + a2 + a3);
    dq += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    t = k * kDt;
    truth.on = t >= kT_on - 1e-9 && t < kT_off - 1e-9;
    tau = controller(t, q, dq);

    // --- the base sensor: what the robot discharges, in the sensor frame ---
    const VectorX ddq = acceleration(model, sim, truth, q, dq, tau);
    ExternalWrench w;
    const int nw = truth.wrench(sim, w);
    rnea(model, sim, q, dq, ddq, std::span<const ExternalWrench>(&w, nw));
    const Vector6 reading = sensor_reading(sim, options.sensor.pose);

    // --- the estimator: one real-time update ---
    const auto start = std::chrono::steady_clock::now();
    const Status status = estimator.update(t, q, dq, tau, reading);
    const double us =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    worst_us = std::max(worst_us, us);
    total_us += us;
    ++updates;
    if (!status.ok()) {
      std::printf("update failed: %s\n", std::string(to_string(status.code)).c_str());
      return 1;
    }
    if (k % 100 == 0) {
      const ContactEstimate& e = estimator.result();
      const double err = nw > 0 ? (e.force_W - w.force_W).norm() : std::nan("");
      std::printf("%6.2f %7d %5s [%7.2f %7.2f %7.2f] [%7.3f %7.3f %7.3f] %8.3f  %s\n", t,
                  e.contact ? 1 : 0, e.contact ? std::string(e.link_name).c_str() : "-",
                  e.force_W.x(), e.force_W.y(), e.force_W.z(), e.point_W.x(), e.point_W.y(),
                  e.point_W.z(), err, describe_flags(e.flags).c_str());
    }
  }
  std::printf("estimator update: mean %.2f us, worst %.2f us over %d samples\n", total_us / updates,
              worst_us, updates);
  return 0;
}
