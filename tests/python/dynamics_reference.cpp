// The C++ side of tests/python/test_dynamics.py: the library's dynamics on inputs read from
// stdin, printed with round-trip precision, so the bindings can be compared bit for bit.
// Usage: dynamics_reference ROBOT < "q.. dq.. ddq.. tau.. body px py pz fx fy fz mx my mz"
#include <cstdio>
#include <iostream>
#include <vector>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/io/robot_loader.hpp"

using namespace extwrench;

namespace {

void print(const char* name, const Eigen::Ref<const MatrixX>& m) {
  std::printf("%s", name);
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) std::printf(" %.17g", m(i, j));
  std::printf("\n");
}

VectorX read(int n) {
  VectorX v(n);
  for (int i = 0; i < n; ++i) std::cin >> v[i];
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dynamics_reference ROBOT < inputs\n");
    return 2;
  }
  const RobotDescription robot = load_robot(argv[1]);
  const Model& model = robot.model;
  const int n = model.nq();
  Data data(model);
  const VectorX q = read(n), dq = read(n), ddq = read(n), tau = read(n);
  ExternalWrench w;
  std::cin >> w.body;
  w.point_W = read(3);
  w.force_W = read(3);
  w.moment_W = read(3);
  if (!std::cin) {
    std::fprintf(stderr, "dynamics_reference: expected %d numbers on stdin\n", 4 * n + 10);
    return 2;
  }
  print("rnea", rnea(model, data, q, dq, ddq));
  print("sensor_reading", sensor_reading(data, default_sensor_pose(model)));
  const std::vector<ExternalWrench> wrenches{w};
  print("rnea_wrench", rnea(model, data, q, dq, ddq, wrenches));
  print("sensor_reading_wrench", sensor_reading(data, default_sensor_pose(model)));
  print("crba", crba(model, data, q));
  print("bias", bias_torques(model, data, q, dq));
  print("gravity", gravity_torques(model, data, q));
  print("coriolis_matrix", coriolis_matrix(model, data, q, dq));
  forward_kinematics(model, data, q);
  print("jacobian_body", body_jacobian(model, data, w.body));
  Matrix6X J(6, n);
  point_jacobian(model, data, w.body, w.point_W, J);
  print("jacobian_point", J);
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Pose& X = data.X_WB[static_cast<std::size_t>(b)];
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = X.rotation;
    T.topRightCorner<3, 1>() = X.translation;
    print(("pose_" + std::to_string(b)).c_str(), T);
  }
  if (!forward_dynamics(model, data, q, dq, tau)) return 1;
  print("forward_dynamics", data.ddq);
  return 0;
}
