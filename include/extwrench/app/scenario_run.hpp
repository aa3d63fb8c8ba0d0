// Running a simulation scenario (io/scenario_config.hpp): the engine of `extwrench simulate`.
// Per seed: the closed-loop simulation writes the log, then every scheme's estimator is replayed
// on it through replay_log (app/replay.hpp), as `extwrench estimate` would.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "extwrench/app/replay.hpp"
#include "extwrench/io/scenario_config.hpp"

namespace extwrench {

struct SchemeResult {
  std::string name;
  ReplayResult replay;
};

struct SeedResult {
  std::uint64_t seed = 0;
  std::filesystem::path dir;
  long samples = 0;
  double peak_condition = 0.0;  ///< max of cond(J of O_l) over the run (true q)
  double peak_time = 0.0;       ///< [s]
  std::vector<SchemeResult> schemes;
};

struct RunOptions {
  bool figures = true;
  bool progress = false;
};

/// Runs the scenario for every seed: DIR (one seed) or DIR/seed_<s> (several) receives
/// log.csv, model_estimator.urdf, and per scheme <scheme>/config.yaml, estimates.csv,
/// metrics.json and figures. The estimates come from replaying log.csv through the same code
/// as `extwrench estimate`, with the configuration read back from <scheme>/config.yaml.
[[nodiscard]] std::vector<SeedResult> run_scenario(const Scenario& scenario,
                                                   const std::filesystem::path& out_dir,
                                                   const RunOptions& options);

}  // namespace extwrench
