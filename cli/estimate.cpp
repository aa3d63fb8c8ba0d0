// extwrench estimate: replays a robot log (real or simulated) through the contact estimator.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "extwrench/app/replay.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench::cli {
namespace {

struct EstimateOptions {
  std::filesystem::path config;
  std::filesystem::path log;
  std::filesystem::path out;
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

void run_estimate(const EstimateOptions& opt) {
  sim::MetricsWindow window{opt.metrics_from, opt.metrics_to, {}};
  std::string description = "t >= " + format_number(opt.metrics_from) + " s";
  for (const auto& e : opt.exclude) {
    window.exclude.push_back(parse_interval(e));
    description += ", excluding [" + e + "] s";
  }
  if (!(opt.plot_points >= 10)) throw UsageError("--plot-points must be at least 10");
  const LoadOptions load = robot_load_options(opt.package_path, opt.lock);
  const EstimatorConfig config = load_estimator_config(opt.config, load);
  check_input_file(opt.log, "log");

  ReplayOptions replay;
  replay.log = opt.log;
  replay.out_dir = opt.out;
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
  if (config.options.sensor.type != SensorType::kNone) {
    std::cout << "extwrench estimate: base sensor pose X_WS: "
              << pose_summary(config.options.sensor.X_WS) << " (" << config.sensor_pose_source
              << ")\n"
              << std::flush;
  }
  const ReplayResult r =
      replay_log(config.robot.model, config.robot.geometry, config.options, replay);

  std::cout << "extwrench estimate: " << r.rows << " rows -> "
            << (opt.out / "estimates.csv").string() << "\n";
  if (r.has_truth) {
    const sim::Metrics& m = r.report.windows.front().metrics;
    std::cout << "  metrics (" << description << "), as in `extwrench simulate`:\n" << std::flush;
    print_metrics_header();
    print_metrics_row(replay.name, "-", m, nullptr, NAN);
    std::fflush(stdout);
    std::cout << "  -> " << (opt.out / "metrics.json").string() << "\n";
  }
  for (const auto& f : r.figures) std::cout << "  figure: " << f.string() << "\n";
  for (const auto& f : r.figure_failures) std::cout << "  figure NOT drawn: " << f << "\n";
}

}  // namespace

void register_estimate(CLI::App& app) {
  auto opt = std::make_shared<EstimateOptions>();
  CLI::App* sub = app.add_subcommand(
      "estimate",
      "Replay a robot log through the contact estimator: estimates.csv, and with truth columns "
      "metrics.json; PNG figures (docs/log_format.md)");
  sub->add_option("--config", opt->config, "Estimator configuration (YAML, docs/config.md)")
      ->required()
      ->type_name("CONFIG.yaml");
  sub->add_option("--log", opt->log, "Robot log (CSV, docs/log_format.md)")
      ->required()
      ->type_name("LOG.csv");
  sub->add_option("--out", opt->out, "Output directory (created)")->required()->type_name("DIR");
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
  sub->callback([opt]() { run_estimate(*opt); });
}

}  // namespace extwrench::cli
