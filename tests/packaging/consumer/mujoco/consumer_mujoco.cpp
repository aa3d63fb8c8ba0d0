// Loads an installed MJCF robot through load_robot (the MJCF reader registered) and checks the
// base reading of the robot at rest against its weight. Exit 0 on success.
#include <cmath>
#include <cstdio>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer_mujoco ROBOT.xml\n");
    return 2;
  }
  extwrench::mujoco::register_mjcf_loader();
  const extwrench::RobotDescription robot = extwrench::load_robot(argv[1]);
  extwrench::Data data(robot.model);
  const int n = robot.model.nq();
  const extwrench::VectorX zero = extwrench::VectorX::Zero(n);
  (void)extwrench::rnea(robot.model, data, extwrench::VectorX::Constant(n, 0.4), zero, zero);
  const extwrench::Vector6 reading = extwrench::sensor_reading(data, extwrench::Pose::identity());
  const double weight = robot.model.total_mass() * robot.model.gravity.norm();
  std::printf("%s: %d joints, %zu shapes, fs_z = %.12g N, weight %.12g N\n", argv[1], n,
              robot.geometry.shapes.size(), reading[2], weight);
  return std::abs(reading[2] + weight) <= 1e-9 * weight ? 0 : 1;
}
