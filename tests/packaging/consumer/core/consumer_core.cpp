// Builds a one-joint pendulum with the core library only and checks its gravity torque
// against the closed form -m g l cos(q). Exit 0 on success.
#include <cmath>
#include <cstdio>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/model/model_builder.hpp"

int main() {
  using namespace extwrench;
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
  return std::abs(tau - expected) <= 1e-12 * std::abs(expected) ? 0 : 1;
}
