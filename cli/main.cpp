// extwrench: the command-line tool. Subcommands live one per file (commands.hpp).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/nearest_name.hpp"
#ifdef EXTWRENCH_HAVE_MUJOCO
#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/bridges/mujoco_engine.hpp"
#endif

#ifndef EXTWRENCH_VERSION
#define EXTWRENCH_VERSION "unknown"
#endif

namespace {

constexpr int kExitInputError = 1;
constexpr int kExitUsageError = 2;

constexpr const char* kFooter = R"(
Examples:
  extwrench info models/paper_arm.urdf
      what the model contains: links, joints, masses, frames, sensor pose, collision shapes
  extwrench dynamics --robot models/paper_arm.yaml --in states.csv --out predicted.csv
      joint torques and the base sensor reading for each row t, q1..qn, dq1..dqn, ddq1..ddqn
  extwrench dynamics --robot arm.urdf --sensor-pose "0 0 -0.05 0 0 3.1416" --in states.csv --out -
      the same with the sensor 5 cm below the root link, turned by 180 deg; CSV to stdout
  extwrench simulate scenarios/paper.yaml --out results/paper
      the paper's experiment: closed-loop simulation, then every estimator scheme on its log
  extwrench estimate --config scheme.yaml --log log.csv --out results/replay
      replay a recorded (or simulated) log through the contact estimator
  extwrench estimate --config scheme.yaml --log 'logs/*.csv' --out results/sweep --jobs 2
      every log matching the pattern, two at a time; results/sweep/<log name>/estimates.csv...
  extwrench COMMAND --help
      all options of one command, with its examples

Units are SI and radians throughout. Exit status: 0 success, 1 bad input file, 2 bad command line.
Documentation: docs/cli.md (commands, CSV), docs/log_format.md, docs/config.md, README.md.)";

// A first argument that is neither an option nor a command: CLI11 says only "A subcommand is
// required", without naming what was typed.
std::string unknown_command(const CLI::App& app, const std::string& word) {
  std::string names;
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    names += (names.empty() ? "" : ", ") + sub->get_name();
    commands.push_back(sub->get_name());
  }
  const std::string nearest = extwrench::nearest_name(word, commands);  // only a near miss
  return "unknown command '" + word + "'" +
         (nearest.empty() ? std::string(".") : "; did you mean '" + nearest + "'?") +
         " The commands are " + names + ".";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "extwrench: external wrench and contact estimation for robot arms, from joint torques, a\n"
      "momentum observer and an optional base force/torque sensor (Buondonno & De Luca, 2016).",
      "extwrench"};
  app.set_version_flag("--version", std::string("extwrench ") + EXTWRENCH_VERSION,
                       "Print the version and exit");
  app.require_subcommand(1);
  app.footer(kFooter);

#ifdef EXTWRENCH_HAVE_MUJOCO
  extwrench::mujoco::register_mjcf_loader();    // load_robot reads MJCF (docs/mujoco.md)
  extwrench::mujoco::register_mujoco_engine();  // scenarios with engine: mujoco
#endif
  // One line per subcommand; each lives in its own file.
  extwrench::cli::register_info(app);
  extwrench::cli::register_dynamics(app);
  extwrench::cli::register_estimate(app);
  extwrench::cli::register_simulate(app);
  extwrench::cli::register_calibrate(app);

  if (argc <= 1) {  // a newcomer typing just `extwrench` gets the help, not an error
    std::cout << app.help();
    return kExitUsageError;
  }
  const std::string first = argv[1];
  if (first == "help") {  // as git and cargo read it
    std::cout << app.help();
    return 0;
  }
  if (!first.empty() && first[0] != '-' &&
      app.get_subcommands([&](const CLI::App* sub) { return sub->check_name(first); }).empty()) {
    std::cerr << "extwrench: usage error: " << unknown_command(app, first)
              << "\nRun with --help for more information.\n";
    return kExitUsageError;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsageError;
  } catch (const extwrench::cli::UsageError& e) {
    std::cerr << "extwrench: usage error: " << e.what()
              << "\nRun with --help for more information.\n";
    return kExitUsageError;
  } catch (const extwrench::Error& e) {
    std::cerr << "extwrench: error: " << e.what() << "\n";
    return kExitInputError;
  } catch (const std::exception& e) {
    std::cerr << "extwrench: error: " << e.what() << "\n";
    return kExitInputError;
  }
  // What the command printed must have reached stdout: `info > /dev/full` (a full disk) is a
  // failure, not a success whose output was lost.
  std::cout.flush();
  if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
    std::cerr << "extwrench: error: <stdout>: write failed (disk full or file removed?)\n";
    return kExitInputError;
  }
  return 0;
}
