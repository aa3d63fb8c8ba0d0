// Replaying a robot log through the contact estimator: the engine of `extwrench estimate`, and
// of `extwrench simulate`, which replays the log it just wrote through the very same code.
// Streaming: memory does not depend on the log's length (figures are decimated). Three threads
// share the work: one reads and parses the log, the calling thread estimates, one formats and
// writes estimates.csv; they hand rows along in batches recycled through fixed rings. A replay
// given one core (ReplayOptions::pipelined false) does all three on the calling thread.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "extwrench/app/contact_tally.hpp"
#include "extwrench/app/gnuplot.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/metrics_json.hpp"
#include "extwrench/io/output_files.hpp"
#include "extwrench/sim/trajectory.hpp"

namespace extwrench {

struct ReplayWindow {
  std::string name;
  std::string description;
  sim::MetricsWindow window;
};

struct ReplayOptions {
  std::filesystem::path log;
  std::filesystem::path out_dir;  ///< estimates.csv, metrics.json, figures go here
  std::string name;               ///< run name in titles and the report (scheme)
  std::string config_label;       ///< the configuration file, for the report
  /// Metric windows; empty: one window over the whole log.
  std::vector<ReplayWindow> windows;
  bool surface_metrics = false;  ///< report the surface-point error
  bool figures = true;
  FigureFormat figure_format = FigureFormat::kPng;
  /// The trajectory the log's controller tracked (simulate): q_d in the joint figure; or null.
  const sim::SinusoidalTrajectory* desired_trajectory = nullptr;
  int plot_points = 2000;  ///< decimation target per figure
  int snapshots = 4;       ///< instants of the 3-D view
  bool progress = false;   ///< progress line on stderr
  /// Parse the log and write estimates.csv on two threads of their own beside the calling,
  /// estimating one (about 1.8 cores busy); false: all three on the calling thread, for a
  /// replay given one core (`--jobs`, replays_pipelined). The bytes written are the same.
  bool pipelined = true;
  bool warn_ignored_columns = true;  ///< list unknown log columns once on stderr
  /// Joint columns beyond the robot's n (q8 on a 7-joint robot) are an error unless this is set
  /// (then they are ignored, with the note of warn_ignored_columns).
  bool ignore_extra_joint_columns = false;
  /// Warn on stderr when most contact samples carry `disagreement` (wrong sensor pose...).
  bool warn_disagreement = true;
  /// Warn on stderr about joint positions far outside the model's limits (a log in degrees);
  /// `simulate` notes a motion past the limits itself.
  bool warn_joint_range = true;
  /// Note on stderr when a log without truth has contacts that look like the model's error
  /// (frequent_alarms_note): `estimate` sets it when the configuration includes no calibration.
  bool note_frequent_alarms = false;
  /// Where the notes and warnings go (ignored columns, figures not drawn, disagreement); null:
  /// std::cerr. Replays running in parallel each get their own buffer, printed in order.
  std::ostream* messages = nullptr;
  /// The command's output transaction (a scenario run's); null: the replay is its own, kept
  /// when it succeeds. Either way a failed replay leaves no estimates.csv or metrics.json.
  OutputFiles* outputs = nullptr;
};

struct ReplayResult {
  long rows = 0;
  bool has_truth = false;
  MetricsReport report;  ///< empty windows without truth
  std::vector<std::filesystem::path> figures;
  std::vector<std::string> figure_failures;  ///< one per figure not drawn (warned on stderr)
  /// The estimates at a glance: contact samples, episodes, samples per link (contact_tally.hpp).
  ContactTally contacts;
};

/// Reads `options.log` row by row, runs a ContactEstimator built from (model, geometry,
/// estimator) on it, writes out_dir/estimates.csv, and with truth columns out_dir/metrics.json;
/// figures (PNG, gnuplot) unless disabled. The first row resets the estimator (its output row is
/// "free" with a zero residual). Throws extwrench::Error on malformed logs (file, line, column)
/// and when the log lacks the columns the configuration's sensor needs, or has joint columns
/// beyond the robot's n (unless ignore_extra_joint_columns). A figure that cannot be drawn is a
/// warning (figure_failures), never an error: the estimates and metrics stand; a malformed row
/// fails after every row before it was estimated, and leaves no output (estimates.csv is written as
/// estimates.csv.partial and renamed at the end; see OutputFiles).
ReplayResult replay_log(const Model& model, const GeometryModel& geometry,
                        const EstimatorOptions& estimator, const ReplayOptions& options);

}  // namespace extwrench
