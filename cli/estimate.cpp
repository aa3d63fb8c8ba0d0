// extwrench estimate: replays robot logs (real or simulated) through the contact estimator,
// several at once with --jobs.
#include <glob.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "extwrench/app/jobs.hpp"
#include "extwrench/app/replay.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench::cli {
namespace {

struct EstimateOptions {
  std::filesystem::path config;
  std::vector<std::string> logs;  // files or patterns
  std::filesystem::path out;
  int jobs = 1;
  // As `simulate` (a scenario's metrics.from default): after the residual's transient.
  double metrics_from = 0.2;
  double metrics_to = std::numeric_limits<double>::infinity();
  std::vector<std::string> exclude;
  bool surface_metrics = false;
  bool no_figures = false;
  int plot_points = 2000;
  std::string figure_format = "png";
  bool ignore_extra_joints = false;
  std::vector<std::filesystem::path> package_path;
  std::vector<std::string> lock;
  std::string root_body, tip_body;  ///< MJCF only
};

std::pair<double, double> parse_interval(const std::string& text) {
  const auto colon = text.find(':');
  const auto a = colon == std::string::npos ? std::nullopt : parse_number(text.substr(0, colon));
  const auto b = colon == std::string::npos ? std::nullopt : parse_number(text.substr(colon + 1));
  if (!a || !b || !(*a < *b)) {
    throw UsageError("--exclude: expected FROM:TO in seconds with FROM < TO, got '" + text + "'");
  }
  return {*a, *b};
}

// The logs of the --log values: a value naming a file is that file; one with *, ? or [ that
// names no file is a pattern, expanded here with glob(3) (sorted), so that a quoted pattern
// works without a shell and never hits the shell's argument limit.
struct LogInputs {
  std::vector<std::filesystem::path> logs;
  bool per_log_dirs = false;  // DIR/<log stem>/ per log: several logs, or any pattern
};

LogInputs expand_logs(const std::vector<std::string>& values) {
  LogInputs in;
  for (const std::string& value : values) {
    std::error_code ec;
    if (value.find_first_of("*?[") == std::string::npos || std::filesystem::exists(value, ec)) {
      in.logs.emplace_back(value);
      continue;
    }
    in.per_log_dirs = true;
    glob_t matches{};
    const int rc = ::glob(value.c_str(), 0, nullptr, &matches);
    for (std::size_t i = 0; rc == 0 && i < matches.gl_pathc; ++i)
      in.logs.emplace_back(matches.gl_pathv[i]);
    ::globfree(&matches);
    if (rc != 0) throw Error("--log '" + value + "': no file matches the pattern");
  }
  in.per_log_dirs = in.per_log_dirs || in.logs.size() > 1;
  return in;
}

// DIR/<stem>/ per log; two logs of one stem would write the same files: a usage error.
std::vector<std::filesystem::path> output_dirs(const LogInputs& in,
                                               const std::filesystem::path& out) {
  std::vector<std::filesystem::path> dirs;
  std::map<std::string, std::filesystem::path> by_stem;
  for (const auto& log : in.logs) {
    if (!in.per_log_dirs) {
      dirs.push_back(out);
      continue;
    }
    const std::string stem = log.stem().string();
    const auto [it, fresh] = by_stem.emplace(stem, log);
    if (!fresh) {
      throw UsageError("--log: " + it->second.string() + " and " + log.string() +
                       " would both write " + (out / stem).string() +
                       "/ (with several logs, each one's outputs go to DIR/<file name without "
                       ".csv>/): rename one, or replay them separately");
    }
    dirs.push_back(out / stem);
  }
  return dirs;
}

// One log's replay; what it prints goes to `console` (a buffer when jobs run in parallel).
void estimate_log(const EstimatorConfig& config, ReplayOptions replay,
                  const std::string& description, std::ostream& console) {
  const ReplayResult r =
      replay_log(config.robot.model, config.robot.geometry, config.options, replay);
  console << "extwrench estimate: " << r.rows << " rows -> "
          << (replay.out_dir / "estimates.csv").string() << "\n";
  console << "  " << contact_summary(r.contacts, config.robot.model) << "\n";
  if (r.has_truth) {
    const sim::Metrics& m = r.report.windows.front().metrics;
    console << "  metrics (" << description << "), as in `extwrench simulate`:\n"
            << metrics_header() << metrics_row(replay.name, "-", m, nullptr, NAN);
    console << "  -> " << (replay.out_dir / "metrics.json").string() << "\n";
    if (m.samples == 0) {  // a row of dashes without a word would read as a failed estimator
      (replay.messages != nullptr ? *replay.messages : std::cerr)
          << "extwrench estimate: warning: the metrics window (" << description
          << ") holds none of the log's samples (t from " << format_number(r.contacts.t_begin)
          << " to " << format_number(r.contacts.t_end)
          << " s): its metrics are empty; see --metrics-from, --metrics-to and --exclude\n";
    }
  }
  for (const auto& f : r.figures) console << "  figure: " << f.string() << "\n";
  for (const auto& f : r.figure_failures) console << "  figure NOT drawn: " << f << "\n";
}

// Each log is its own transaction (OutputFiles): a failed log leaves nothing behind, the
// others' outputs are complete and stay. One log: its error as it is; several: each error was
// printed in its place, and the command fails naming the failed logs.
void report_failures(const std::vector<std::filesystem::path>& logs, const JobOutcomes& outcomes,
                     OutputFiles& top) {
  if (outcomes.first_failure() == logs.size()) {
    top.keep();
    return;
  }
  if (logs.size() == 1) std::rethrow_exception(outcomes.errors.front());
  std::string names;
  std::size_t failed = 0;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    if (!outcomes.errors[i]) continue;
    ++failed;
    names += (names.empty() ? "" : ", ") + logs[i].string();
  }
  if (failed < logs.size()) top.keep();
  throw Error(std::to_string(failed) + " of " + std::to_string(logs.size()) +
              " logs failed (no output for them; the other logs' outputs are complete): " + names);
}

ReplayOptions replay_options(const EstimateOptions& opt, const std::string& description) {
  sim::MetricsWindow window{opt.metrics_from, opt.metrics_to, {}};
  for (const auto& e : opt.exclude) window.exclude.push_back(parse_interval(e));
  ReplayOptions replay;
  replay.name = opt.config.stem().string() == "config" && opt.config.has_parent_path()
                    ? opt.config.parent_path().filename().string()
                    : opt.config.stem().string();
  replay.config_label = opt.config.string();
  replay.windows.push_back({"window", description, window});
  replay.surface_metrics = opt.surface_metrics;
  replay.figures = !opt.no_figures;
  replay.figure_format = *parse_figure_format(opt.figure_format);  // checked by CLI11
  replay.ignore_extra_joint_columns = opt.ignore_extra_joints;
  replay.plot_points = opt.plot_points;
  replay.progress = true;  // a line rewritten on a terminal, periodic lines elsewhere
  return replay;
}

void run_estimate(const EstimateOptions& opt) {
  refuse_dash(opt.out, "--out",
              "estimate writes a directory of files, not standard output; give a directory path");
  // NaN fails every comparison: say so, not that the other bound is out of order.
  if (std::isnan(opt.metrics_from))
    throw UsageError("--metrics-from: expected a time in seconds, got nan");
  if (std::isnan(opt.metrics_to))
    throw UsageError("--metrics-to: expected a time in seconds, got nan");
  if (!(opt.metrics_from < opt.metrics_to)) {
    throw UsageError("--metrics-to " + format_number(opt.metrics_to) +
                     " must come after --metrics-from " + format_number(opt.metrics_from) +
                     " (the metrics window is from <= t <= to)");
  }
  std::string description = "t >= " + format_number(opt.metrics_from) + " s";
  if (std::isfinite(opt.metrics_to))
    description += ", t <= " + format_number(opt.metrics_to) + " s";
  for (const auto& e : opt.exclude) description += ", excluding [" + e + "] s";
  ReplayOptions common = replay_options(opt, description);  // checks --exclude
  if (!(opt.plot_points >= 10)) throw UsageError("--plot-points must be at least 10");
  const LogInputs inputs = expand_logs(opt.logs);
  const std::vector<std::filesystem::path> dirs = output_dirs(inputs, opt.out);
  const LoadOptions load =
      robot_load_options(opt.package_path, opt.lock, opt.root_body, opt.tip_body);
  const EstimatorConfig config = load_estimator_config(opt.config, load);
  for (const auto& log : inputs.logs) check_input_file(log, "log");
  common.note_frequent_alarms = config.calibration_path.empty();
  if (config.options.sensor.type != SensorType::kNone) {
    std::cout << "extwrench estimate: base sensor pose X_WS: "
              << pose_summary(config.options.sensor.X_WS) << " (" << config.sensor_pose_source
              << ")\n"
              << std::flush;
  }
  const std::size_t count = inputs.logs.size();
  // Jobs = whole replays, N at once on --jobs N cores: each its own three-thread pipeline
  // (reader, estimator, writer; app/replay.hpp) when it has two cores or more, else each on one
  // thread, so that --jobs N keeps N cores busy, not 1.8 N.
  const bool pipelined = replays_pipelined(opt.jobs, count);
  const bool serial = opt.jobs == 1 || count == 1;
  std::vector<std::ostringstream> messages(count), printed(count);
  OutputFiles top;  // DIR itself, removed again if every log fails
  if (inputs.per_log_dirs) top.create_directories(opt.out);
  const JobOutcomes outcomes = run_jobs(
      count,
      [&](std::size_t i) {
        ReplayOptions replay = common;
        replay.log = inputs.logs[i];
        replay.out_dir = dirs[i];
        replay.progress = serial;  // parallel progress lines would overwrite one another
        replay.pipelined = pipelined;
        if (count == 1) return estimate_log(config, std::move(replay), description, std::cout);
        replay.messages = &messages[i];
        try {
          estimate_log(config, std::move(replay), description, printed[i]);
        } catch (const std::exception& e) {
          messages[i] << "extwrench: error: " << e.what() << "\n";
          throw;
        }
      },
      {.jobs = opt.jobs},
      [&](std::size_t i) {
        // The replay's notes and warnings name its scheme, not its log: say which log.
        if (!messages[i].str().empty())
          std::cerr << "extwrench: " << inputs.logs[i].string() << ":\n" << messages[i].str();
        std::cerr << std::flush;
        std::cout << printed[i].str() << std::flush;
      });
  report_failures(inputs.logs, outcomes, top);
}

}  // namespace

void register_estimate(CLI::App& app) {
  auto opt = std::make_shared<EstimateOptions>();
  CLI::App* sub = app.add_subcommand(
      "estimate",
      "Replay robot logs through the contact estimator: estimates.csv, and with truth columns "
      "metrics.json; PNG figures (docs/log_format.md). Several logs run in parallel (--jobs)");
  sub->add_option("--config", opt->config, "Estimator configuration (YAML, docs/config.md)")
      ->required()
      ->type_name("CONFIG.yaml");
  sub->add_option("--log", opt->logs,
                  "Robot log(s) (CSV, docs/log_format.md): repeatable, several after one --log, "
                  "or a quoted pattern such as 'logs/*.csv'. One log: DIR/estimates.csv...; "
                  "several (or a pattern): DIR/<log file name without .csv>/estimates.csv...")
      ->required()
      ->type_name("LOG.csv");
  sub->add_option("--out", opt->out, "Output directory (created)")->required()->type_name("DIR");
  add_jobs_option(*sub, opt->jobs, "logs replayed");
  sub->add_option("--metrics-from", opt->metrics_from,
                  "Start of the metrics window [s] (default 0.2, after the residual's transient, "
                  "as simulate)")
      ->type_name("T");
  sub->add_option("--metrics-to", opt->metrics_to,
                  "End of the metrics window [s] (default: end of log)")
      ->type_name("T");
  sub->add_option("--exclude", opt->exclude, "Exclude FROM:TO [s] from the metrics (repeatable)")
      ->type_name("FROM:TO");
  sub->add_flag("--surface-metrics", opt->surface_metrics,
                "Report the surface-point error (when the true points lie on the links' surfaces)");
  sub->add_flag("--no-figures", opt->no_figures, "Do not draw figures (no gnuplot needed)");
  sub->add_option("--plot-points", opt->plot_points,
                  "Points per figure after decimation (default 2000)")
      ->type_name("N");
  add_figure_format_option(*sub, opt->figure_format);
  sub->add_flag("--ignore-extra-joints", opt->ignore_extra_joints,
                "Ignore log columns of joints beyond the robot's n (q8.. on a 7-joint robot); "
                "without it they are an error");
  add_package_path_option(*sub, opt->package_path);
  add_lock_option(*sub, opt->lock);
  add_chain_options(*sub, opt->root_body, opt->tip_body);
  sub->footer(help_footer(
      {{"extwrench estimate --config results/paper/seed_1/ft/config.yaml --log "
        "results/paper/seed_1/log.csv --out results/replay",
        "replay the log that `extwrench simulate scenarios/paper.yaml --out results/paper` wrote, "
        "with its base F/T scheme's configuration"},
       {"extwrench estimate --config panda.yaml --log free.csv --out results/panda",
        "a real arm's log (no truth columns): estimates.csv, figures, and a `contact:` summary; "
        "run `extwrench calibrate` first if it reports contacts the arm never had"},
       {"extwrench estimate --config panda.yaml --log 'logs/*.csv' --out results/sweep --jobs 2",
        "every log matching the pattern, two at a time: "
        "results/sweep/<log name>/estimates.csv..."}},
      "docs/cli.md (estimate), docs/config.md (CONFIG.yaml), docs/log_format.md (the CSV "
      "files)"));
  sub->callback([opt]() { run_estimate(*opt); });
}

}  // namespace extwrench::cli
