// The C++ example of README.md, compiled so that it cannot rot. Keep the two in sync.
#include <iostream>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/robot_loader.hpp"

#ifndef EXTWRENCH_MODELS_DIR
#define EXTWRENCH_MODELS_DIR "models"
#endif

int main(int argc, char** argv) {
  using namespace extwrench;
  const std::string file = argc > 1 ? argv[1] : EXTWRENCH_MODELS_DIR "/paper_arm.urdf";

  // README example begins
  const RobotDescription robot = load_robot(file);  // URDF or DH YAML; throws extwrench::Error
  const Model& model = robot.model;                 // constant, validated
  Data data(model);                                 // workspace: all buffers sized once

  const int n = model.nq();
  const VectorX q = VectorX::Constant(n, 0.3), dq = VectorX::Constant(n, 0.1),
                ddq = VectorX::Zero(n);

  // A 20 N push along world x at a point of the last link (no allocation from here on).
  const ExternalWrench push{.body = n, .force_W = {20.0, 0.0, 0.0}, .point_W = {0.1, 0.0, 1.0}};
  const VectorX& tau = rnea(model, data, q, dq, ddq, {&push, 1});  // joint torques [N m]

  // What the robot discharges onto a base F/T sensor at the root origin: [f_m; n_m], sensor frame.
  const Vector6 reading = sensor_reading(data, Pose::identity());
  std::cout << "tau = " << tau.transpose() << "\nbase sensor = " << reading.transpose() << "\n";
  // README example ends
  return 0;
}
