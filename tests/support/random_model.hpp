// Random but physically valid models built directly as Model structs (no parser involved), for
// identity tests of the dynamics: serial chains and trees, revolute and prismatic joints.
#pragma once

#include "extwrench/model/model.hpp"
#include "support/random.hpp"

namespace extwrench::test {

struct RandomModelOptions {
  int n = 7;
  bool tree = false;       ///< random parents instead of a chain
  bool prismatic = false;  ///< some joints prismatic
  unsigned seed = 1;
};

inline Inertia random_inertia(SeededRng& rng) {
  Inertia in;
  in.mass = rng.uniform(0.5, 3.0);
  in.com = rng.uniform_vector3(-0.1, 0.1);
  // Principal moments satisfying the triangle inequality, in random principal axes.
  const Vector3 d(rng.uniform(0.01, 0.05), rng.uniform(0.01, 0.05), rng.uniform(0.01, 0.05));
  const Matrix3 r = Eigen::Quaterniond(Eigen::Vector4d(rng.uniform_vector(4, -1, 1)).normalized())
                        .toRotationMatrix();
  in.inertia_com = r * d.asDiagonal() * r.transpose();
  return in;
}

inline Model random_model(const RandomModelOptions& opt) {
  SeededRng rng(opt.seed);
  Model model;
  model.name = "random";
  model.bodies.resize(static_cast<std::size_t>(opt.n + 1));
  model.joints.resize(static_cast<std::size_t>(opt.n + 1));
  model.parents.resize(static_cast<std::size_t>(opt.n + 1));
  model.parents[0] = -1;
  for (int i = 0; i <= opt.n; ++i) {
    model.bodies[i].name = "link" + std::to_string(i);
    model.bodies[i].inertia = random_inertia(rng);
    model.frames.push_back({model.bodies[i].name, i, Pose{}});
    if (i == 0) continue;
    model.parents[i] = opt.tree ? static_cast<int>(rng.uniform(0.0, i - 1e-9)) : i - 1;
    Joint& j = model.joints[i];
    j.name = "joint" + std::to_string(i);
    j.type = (opt.prismatic && i % 3 == 2) ? JointType::kPrismatic : JointType::kRevolute;
    j.placement = Pose::from_xyz_rpy(rng.uniform_vector3(-0.3, 0.3), rng.uniform_vector3(-3, 3));
    j.axis = rng.uniform_vector3(-1, 1).normalized();
  }
  return model;
}

}  // namespace extwrench::test
