// Loads an installed model file and checks the base reading of the robot at rest against its
// weight. Exit 0 on success.
#include <cmath>
#include <cstdio>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/csv.hpp"
#include "extwrench/io/robot_loader.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer_io ROBOT\n");
    return 2;
  }
  const extwrench::RobotDescription robot = extwrench::load_robot(argv[1]);
  extwrench::Data data(robot.model);
  const int n = robot.model.nq();
  const extwrench::VectorX zero = extwrench::VectorX::Zero(n);
  (void)extwrench::rnea(robot.model, data, extwrench::VectorX::Constant(n, 0.4), zero, zero);
  const extwrench::Vector6 reading = extwrench::sensor_reading(data, extwrench::Pose::identity());
  const double weight = robot.model.total_mass() * 9.81;
  std::printf("%s: %d joints, fs_z = %s N, weight %s N\n", argv[1], n,
              extwrench::CsvWriter::format(reading[2]).c_str(),
              extwrench::CsvWriter::format(weight).c_str());
  return std::abs(reading[2] + weight) <= 1e-9 * weight ? 0 : 1;
}
