// Replays a short log of the robot at rest (written here, without a base sensor) through the
// installed replay pipeline, without figures. Exit 0 when every row was estimated and written.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "extwrench/app/replay.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/io/robot_loader.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer_app ROBOT OUT_DIR\n");
    return 2;
  }
  try {
    const extwrench::RobotDescription robot = extwrench::load_robot(argv[1]);
    const int n = robot.model.nq();
    const std::filesystem::path dir = argv[2];
    std::filesystem::create_directories(dir);
    extwrench::LogLayout layout;
    layout.n = n;
    {
      std::ofstream log(dir / "log.csv");
      std::string header;
      for (const std::string& c : extwrench::log_columns(layout)) {
        header += (header.empty() ? "" : ",") + c;
      }
      log << header << "\n";
      for (int k = 0; k < 5; ++k) {
        log << 0.001 * k;
        for (int c = 0; c < 3 * n; ++c) log << ",0";  // q, dq, tau
        log << "\n";
      }
    }
    extwrench::ReplayOptions options;
    options.log = dir / "log.csv";
    options.out_dir = dir / "replay";
    options.figures = false;
    const extwrench::ReplayResult result =
        extwrench::replay_log(robot.model, robot.geometry, extwrench::EstimatorOptions{}, options);
    std::printf("replayed %ld rows into %s\n", result.rows, options.out_dir.string().c_str());
    return result.rows == 5 && std::filesystem::is_regular_file(options.out_dir / "estimates.csv")
               ? 0
               : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer_app: %s\n", e.what());
    return 1;
  }
}
