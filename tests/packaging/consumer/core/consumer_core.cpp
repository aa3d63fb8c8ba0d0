// Builds a one-joint pendulum with the core library only and checks its gravity torque
// against the closed form -m g l cos(q); then runs the estimator on the paper arm, simulated
// with a 20 N push, and checks its force. The packaging test builds this also with
// -march=native and with AddressSanitizer against the plain library: a consumer's flags must
// not change the layout of what crosses the library's boundary (ContactEstimate's fixed-size
// members, the allocator of its vectors). Exit 0 on success.
#include <cmath>
#include <cstdio>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/model/model_builder.hpp"
#include "extwrench/model/sample_models.hpp"
#include "extwrench/sim/simulator.hpp"

namespace {

using namespace extwrench;

bool pendulum() {
  constexpr double kMass = 1.5, kLength = 0.4, kQ = 0.3;
  ModelBuilder builder;
  builder.set_name("pendulum");
  LinkSpec base;
  base.name = "base";
  base.inertia.mass = 1.0;
  base.inertia.inertia_com = Matrix3::Identity() * 0.01;
  base.source = "consumer";
  LinkSpec arm;
  arm.name = "arm";
  arm.inertia.mass = kMass;
  arm.inertia.com = Vector3(kLength, 0.0, 0.0);
  arm.inertia.inertia_com = Matrix3::Identity() * 1e-3;
  arm.source = "consumer";
  builder.add_link(base);
  builder.add_link(arm);
  JointSpec joint;
  joint.name = "j";
  joint.type = JointSpecType::kRevolute;
  joint.parent = "base";
  joint.child = "arm";
  // About +y, q > 0 lowers the arm (CoM at (l cos q, 0, -l sin q)); gravity's moment about the
  // axis is r x (0, 0, -m g) = +m g l cos q, so holding the arm takes tau = -m g l cos q.
  joint.axis = Vector3::UnitY();
  joint.source = "consumer";
  builder.add_joint(joint);
  const Model model = builder.build();
  Data data(model);
  VectorX q(1), zero = VectorX::Zero(1);
  q << kQ;
  const double tau = rnea(model, data, q, zero, zero)[0];
  const double expected = -kMass * 9.81 * kLength * std::cos(kQ);
  std::printf("pendulum: tau = %.12g, -m g l cos q = %.12g\n", tau, expected);
  return std::abs(tau - expected) <= 1e-12 * std::abs(expected);
}

// The paper arm held near a pose and pushed with 20 N along world x at a point of link 6 from
// t = 0.5 s; the estimate at 1 s, through a base F/T sensor, within 1 N of it.
bool estimator() {
  const Model model = paper_arm();
  const int n = model.nq();
  sim::SinusoidalTrajectory desired{VectorX::Constant(n, 0.3), VectorX::Constant(n, 0.1),
                                    VectorX::Constant(n, 0.5), VectorX::Zero(n)};
  const sim::PidGains pd{VectorX::Constant(n, 100.0), VectorX::Constant(n, 20.0), VectorX::Zero(n)};
  sim::SimulationConfig config;
  config.duration = 1.0;
  sim::ForceProfile push;
  push.frame = "link6";
  push.axes = sim::ForceProfile::Axes::kWorld;
  push.force = Vector3(20.0, 0.0, 0.0);
  push.start = 0.5;
  config.forces.push_back(push);
  sim::Simulator simulator(model, sim::ComputedTorqueController(model, desired, pd), config);
  EstimatorOptions options;
  options.sensor.type = SensorType::kForceTorque;
  options.sensor.X_WS = config.sensor.X_WS;
  options.contact.model = ContactModel::kPureForce;
  ContactEstimator est(model, GeometryModel{}, options);
  Sample s;
  if (!simulator.next(s) || !est.reset(s.t, s.q, s.dq, s.tau).ok()) return false;
  while (simulator.next(s)) {
    if (const Status status = est.update(s); !status.ok()) {
      std::printf("estimator: update failed at t = %g\n", s.t);
      return false;
    }
  }
  const ContactEstimate& e = est.result();
  std::printf("estimator: contact %d, F = (%.3f, %.3f, %.3f) N, true (%.3f, %.3f, %.3f) N\n",
              e.contact ? 1 : 0, e.force_W.x(), e.force_W.y(), e.force_W.z(), s.truth.force_W.x(),
              s.truth.force_W.y(), s.truth.force_W.z());
  return e.contact && (e.force_W - Vector3(20.0, 0.0, 0.0)).norm() < 1.0;
}

}  // namespace

int main() { return pendulum() && estimator() ? 0 : 1; }
