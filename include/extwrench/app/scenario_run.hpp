// Running a simulation scenario (io/scenario_config.hpp): the engine of `extwrench simulate`.
// Per seed: the closed-loop simulation writes the log, then every scheme's estimator is replayed
// on it through replay_log (app/replay.hpp), as `extwrench estimate` would.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
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
  /// The crossings: time spans where cond(J of O_l) > the scenario's singularity_threshold.
  std::vector<std::pair<double, double>> singular_spans;
  /// Notes on the scenario printed after the simulation: an applied force whose point is not
  /// where a pusher along it meets the arm, when a scheme isolates on geometry.
  std::vector<std::string> notes;
  std::vector<SchemeResult> schemes;
};

struct RunOptions {
  bool figures = true;
  bool progress = false;  ///< progress lines on stderr (only with jobs == 1)
  FigureFormat figure_format = FigureFormat::kPng;
  /// Seeds simulated, then (seed, scheme) replays run, this many at once (app/jobs.hpp). The
  /// files and results do not depend on it: each job has its own random streams and files.
  int jobs = 1;
  /// The replays' notes and warnings, each replay's together, in (seed, scheme) order; null:
  /// std::cerr.
  std::ostream* messages = nullptr;
};

/// The run's summary across seeds (several seeds, figures on): DIR/summary.<format> with its
/// data and script, the force and line-of-action errors of every scheme per seed and the
/// scenario's targets. Empty when not drawn; a failure is a warning on stderr (as a replay's).
struct RunSummary {
  std::filesystem::path figure;
};

/// Runs the scenario for every seed: DIR (one seed) or DIR/seed_\<s\> (several) receives
/// log.csv, model_estimator.urdf, and per scheme <scheme>/config.yaml, estimates.csv,
/// metrics.json and figures. The estimates come from replaying log.csv through the same code
/// as `extwrench estimate`, with the configuration read back from <scheme>/config.yaml.
/// A failure (the lowest failing seed, then scheme: the one a serial run meets first, named
/// "seed S, scheme 'X': ..." with several seeds) removes every file of the run.
[[nodiscard]] std::vector<SeedResult> run_scenario(const Scenario& scenario,
                                                   const std::filesystem::path& out_dir,
                                                   const RunOptions& options,
                                                   RunSummary* summary = nullptr);

/// The value of a target's metric in a scheme's results (NaN when the run has no such window).
[[nodiscard]] double target_metric(const ReplayResult& replay, const std::string& metric);

}  // namespace extwrench
