#include "extwrench/model/sample_models.hpp"

#include <numbers>
#include <string>

#include "extwrench/core/random.hpp"

namespace extwrench {
namespace {

// The paper's Table II (signs restored) and its link 0, per link i = 1..7 in DH frame i.
constexpr double kPi = std::numbers::pi;
constexpr double kAlpha[7] = {kPi / 2, -kPi / 2, -kPi / 2, kPi / 2, kPi / 2, -kPi / 2, 0};  // [rad]
constexpr double kD[7] = {0, 0, 0.40, 0, 0.39, 0, 0.078};                                   // [m]
constexpr double kMass[7] = {2.7, 2.7, 2.7, 2.7, 2.7, 1.7, 0.3};                            // [kg]
constexpr double kComCm[7][3] = {{0.1340, -8.7777, 2.6220},
                                 {0.1340, 2.6220, 8.7777},
                                 {0.1340, 8.7777, 2.6220},
                                 {0.1340, 2.6220, 8.7777},
                                 {0.1340, -8.7777, 2.6220},
                                 {0, 0.5, 0},
                                 {0, 0, -2.0}};  // [cm]
// Ixx Ixy Ixz Iyy Iyz Izz about the CoM, DH frame i axes [g m^2].
constexpr double kInertiaGm2[7][6] = {{16.341, 0.003, 0.001, 5.026, -3.533, 16.173},
                                      {16.341, 0.001, 0.003, 16.173, 3.533, 5.026},
                                      {16.341, 0.003, 0.001, 5.026, 3.533, 16.173},
                                      {16.341, 0.001, 0.003, 16.173, 3.533, 5.026},
                                      {16.341, 0.003, 0.001, 5.026, -3.533, 16.173},
                                      {5.0, 0, 0, 3.6, 0, 4.7},
                                      {1.0, 0, 0, 1.0, 0, 1.0}};
constexpr double kLink0Height = 0.31;                       // O_0 above the sensor [m]
constexpr double kLink0Mass = 2.0;                          // [kg]
constexpr double kLink0ComZ = 0.15;                         // [m], in link 0's frame
constexpr double kLink0Inertia[3] = {0.020, 0.020, 0.010};  // Ixx Iyy Izz about the CoM [kg m^2]

Pose dh_transform(double d, double alpha) {
  // Standard DH with a = 0 and θ folded into the joint: Tz(d) Rx(α).
  Pose x;
  x.translation = Vector3(0, 0, d);
  x.rotation = Eigen::AngleAxisd(alpha, Vector3::UnitX()).toRotationMatrix();
  return x;
}

Vector3 uniform_vector3(Rng& rng, double lo, double hi) {
  const double x = rng.uniform(lo, hi);
  const double y = rng.uniform(lo, hi);
  const double z = rng.uniform(lo, hi);
  return {x, y, z};
}

Inertia random_inertia(Rng& rng) {
  Inertia in;
  in.mass = rng.uniform(0.5, 3.0);
  in.com = uniform_vector3(rng, -0.1, 0.1);
  // Principal moments satisfying the triangle inequality, in random principal axes.
  const Vector3 d = uniform_vector3(rng, 0.01, 0.05);
  Eigen::Vector4d axes;
  for (int k = 0; k < 4; ++k) axes[k] = rng.uniform(-1, 1);
  const Matrix3 r = Eigen::Quaterniond(axes.normalized()).toRotationMatrix();
  in.inertia_com = r * d.asDiagonal() * r.transpose();
  return in;
}

}  // namespace

Model paper_arm() {
  Model m;
  m.name = "paper_arm";
  m.bodies.resize(8);
  m.joints.resize(8);
  m.parents.resize(8);
  m.parents[0] = -1;
  m.bodies[0].name = "link0";
  m.bodies[0].inertia.mass = kLink0Mass;
  m.bodies[0].inertia.com = Vector3(0, 0, kLink0ComZ);
  m.bodies[0].inertia.inertia_com =
      Vector3(kLink0Inertia[0], kLink0Inertia[1], kLink0Inertia[2]).asDiagonal();
  m.frames.push_back({"link0", 0, Pose{}});
  for (int i = 1; i <= 7; ++i) {
    const int k = i - 1;
    m.parents[i] = i - 1;
    Joint& j = m.joints[i];
    j.name = "joint" + std::to_string(i);
    j.axis = Vector3::UnitZ();
    if (i == 1) {
      j.placement.translation = Vector3(0, 0, kLink0Height);
    } else {
      j.placement = dh_transform(kD[k - 1], kAlpha[k - 1]);
    }
    Inertia dh;
    dh.mass = kMass[k];
    dh.com = Vector3(kComCm[k][0], kComCm[k][1], kComCm[k][2]) * 1e-2;
    Matrix3 I;
    const double* in = kInertiaGm2[k];
    I << in[0], in[1], in[2], in[1], in[3], in[4], in[2], in[4], in[5];
    dh.inertia_com = I * 1e-3;
    const Pose X_B_dh = dh_transform(kD[k], kAlpha[k]);
    m.bodies[i].name = "link" + std::to_string(i);
    m.bodies[i].inertia = dh.transformed(X_B_dh);
    m.frames.push_back({m.bodies[i].name, i, Pose{}});
    m.frames.push_back({"dh" + std::to_string(i), i, X_B_dh});
  }
  return m;
}

Model random_chain(const RandomChainOptions& options) {
  Rng rng(options.seed);
  const auto nb = static_cast<std::size_t>(options.n + 1);
  Model model;
  model.name = "random";
  model.bodies.resize(nb);
  model.joints.resize(nb);
  model.parents.resize(nb);
  model.parents[0] = -1;
  for (int i = 0; i <= options.n; ++i) {
    model.bodies[i].name = "link" + std::to_string(i);
    model.bodies[i].inertia = random_inertia(rng);
    model.frames.push_back({model.bodies[i].name, i, Pose{}});
    if (i == 0) continue;
    model.parents[i] = options.tree ? static_cast<int>(rng.uniform(0.0, i - 1e-9)) : i - 1;
    Joint& j = model.joints[i];
    j.name = "joint" + std::to_string(i);
    j.type = (options.prismatic && i % 3 == 2) ? JointType::kPrismatic : JointType::kRevolute;
    const Vector3 xyz = uniform_vector3(rng, -0.3, 0.3);
    const Vector3 rpy = uniform_vector3(rng, -3, 3);
    j.placement = Pose::from_xyz_rpy(xyz, rpy);
    j.axis = uniform_vector3(rng, -1, 1).normalized();
  }
  return model;
}

}  // namespace extwrench
