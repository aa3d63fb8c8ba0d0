// extwrench simulate: runs a scenario (docs/simulation.md) — closed-loop simulation, the log, the
// estimators replayed on it — and prints a table of the metrics.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "extwrench/app/scenario_run.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/io/estimator_config.hpp"

namespace extwrench::cli {
namespace {

struct SimulateOptions {
  std::filesystem::path scenario;
  std::filesystem::path out;
  bool no_figures = false;
  int jobs = 1;
  std::string figure_format = "png";
  std::vector<std::filesystem::path> package_path;
  std::vector<std::string> lock;
  std::string root_body, tip_body;  ///< MJCF only
};

const NamedMetrics* window_named(const ReplayResult& r, const std::string& name) {
  for (const auto& w : r.report.windows) {
    if (w.name == name) return &w;
  }
  return nullptr;
}

std::string cell(double v, const char* format) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// One row per seed, the worst over the seeds, and the scenario's targets for the scheme.
void print_scheme(const Scenario& scenario, const SchemeSpec& scheme,
                  const std::vector<SeedResult>& results) {
  // NaN (printed '-') until a seed has a value: a scenario without a singularity window has no
  // 'F RMS*', a push that never starts (start after the end) no force, line or link, and their
  // worst is not 0 m or 100 %. fmax/fmin skip a seed's NaN.
  double worst_f = NAN, worst_f_outside = NAN, worst_line = NAN, worst_link = NAN;
  for (const SeedResult& r : results) {
    for (const SchemeResult& sr : r.schemes) {
      if (sr.name != scheme.name) continue;
      const NamedMetrics* a = window_named(sr.replay, "after_transient");
      const NamedMetrics* b = window_named(sr.replay, "outside_singularity");
      if (!a) continue;
      const sim::Metrics& m = a->metrics;
      // The peak of cond(J of O_l) is tracked only for a singularity window's link.
      print_metrics_row(scheme.name, std::to_string(r.seed), m, b ? &b->metrics : nullptr,
                        scenario.singularity_link.empty() ? NAN : r.peak_condition);
      worst_f = std::fmax(worst_f, m.force.rms());
      if (b) worst_f_outside = std::fmax(worst_f_outside, b->metrics.force.rms());
      worst_line = std::fmax(worst_line, m.line.rms());
      worst_link = std::fmin(worst_link, m.isolation_accuracy());
    }
  }
  if (results.size() > 1) {
    std::printf("%-12s %6s %10s %9s %9s %8s m %10s %9s\n", scheme.name.c_str(), "worst",
                cell(worst_f, "%.3f").c_str(), "", cell(worst_f_outside, "%.3f").c_str(),
                cell(worst_line, "%.4f").c_str(), "", cell(100.0 * worst_link, "%.2f").c_str());
  }
  for (const MetricTarget& t : scenario.targets) {
    if (t.scheme != scheme.name) continue;
    const bool lower_bound = t.metric == "right_link";
    double worst = lower_bound ? INFINITY : -INFINITY;
    for (const SeedResult& r : results) {
      for (const SchemeResult& sr : r.schemes) {
        if (sr.name != scheme.name) continue;
        const double v = target_metric(sr.replay, t.metric);
        if (std::isfinite(v)) worst = lower_bound ? std::min(worst, v) : std::max(worst, v);
      }
    }
    const bool met = std::isfinite(worst) && (lower_bound ? worst >= t.value : worst <= t.value);
    std::printf("%-12s %6s %s %s %.4g: worst %.4g  %s\n", scheme.name.c_str(), "target",
                t.metric.c_str(), lower_bound ? ">=" : "<=", t.value, worst,
                met ? "met" : "NOT MET");
  }
}

void run_simulate(const SimulateOptions& opt) {
  refuse_dash(opt.out, "--out",
              "simulate writes a directory of files, not standard output; give a directory path");
  const LoadOptions load =
      robot_load_options(opt.package_path, opt.lock, opt.root_body, opt.tip_body);
  const Scenario scenario = load_scenario(opt.scenario, load);
  const Pose& X_WS = scenario.simulation.sensor.X_WS;
  const bool default_pose =
      X_WS.translation == default_sensor_pose(scenario.robot.model).translation &&
      X_WS.rotation == default_sensor_pose(scenario.robot.model).rotation;
  std::fprintf(stderr, "extwrench simulate: base sensor pose X_WS: %s (%s)\n",
               pose_summary(X_WS).c_str(),
               default_pose ? describe_default_sensor_pose(scenario.robot.model).c_str()
                            : "sensors.base.pose");
  // A push that starts after the run ends is accepted (a shortened duration for a quick look),
  // but a table without contact must not come as a surprise.
  const auto& forces = scenario.simulation.forces;
  for (std::size_t i = 0; i < forces.size(); ++i) {
    if (forces[i].start > scenario.simulation.duration) {
      std::fprintf(stderr,
                   "extwrench simulate: note: forces[%zu] starts at t = %g s, after the run's end "
                   "(duration %g s): it never acts\n",
                   i, forces[i].start, scenario.simulation.duration);
    }
  }
  // Likewise metrics windows beside the run: a table of dashes must not read as a failed run.
  const double duration = scenario.simulation.duration;
  if (scenario.metrics_from > duration) {
    std::fprintf(stderr,
                 "extwrench simulate: note: metrics.from is %g s, after the run's end "
                 "(duration %g s): no sample is measured, every metric is empty\n",
                 scenario.metrics_from, duration);
  }
  for (std::size_t i = 0; i < scenario.metrics_exclude.size(); ++i) {
    const auto& [from, to] = scenario.metrics_exclude[i];
    if (from > duration || to < 0.0) {
      std::fprintf(stderr,
                   "extwrench simulate: note: metrics.exclude[%zu] [%g, %g] s lies outside the "
                   "run (0 to %g s): it excludes nothing\n",
                   i, from, to, duration);
    }
  }
  RunOptions run;
  run.figures = !opt.no_figures;
  run.progress = true;  // a line rewritten on a terminal, periodic lines elsewhere (--jobs 1)
  run.jobs = opt.jobs;
  run.figure_format = *parse_figure_format(opt.figure_format);  // checked by CLI11
  RunSummary summary;
  const std::vector<SeedResult> results = run_scenario(scenario, opt.out, run, &summary);

  std::printf(
      "\nextwrench simulate: %s, %zu seed(s), %.3g s at %.3g ms, dynamic parameters ±%g %%\n",
      opt.scenario.string().c_str(), results.size(), scenario.simulation.duration,
      1e3 * scenario.simulation.sample_time, 100.0 * scenario.model_error);
  const std::string from = cell(scenario.metrics_from, "%g");
  if (scenario.singularity_half_width > 0.0) {
    std::printf(
        "Metrics after t = %s s; 'F RMS*' excludes ±%g s around every crossing of cond(J of O_l) "
        "> %g, l = %s.\n\n",
        from.c_str(), scenario.singularity_half_width, scenario.singularity_threshold,
        scenario.singularity_link.c_str());
  } else {
    std::printf(
        "Metrics after t = %s s; no singularity window ('F RMS*', 'peak cond': "
        "metrics.exclude_around_singularity).\n\n",
        from.c_str());
  }
  print_metrics_header();
  for (const SchemeSpec& scheme : scenario.schemes) print_scheme(scenario, scheme, results);
  std::printf(
      "\nOutputs (per seed: log.csv, model_estimator.urdf; per scheme: config.yaml, estimates.csv, "
      "metrics.json, figures):\n");
  for (const SeedResult& r : results) {
    std::printf("  %s\n", r.dir.string().c_str());
  }
  if (!summary.figure.empty())
    std::printf("Summary across seeds: %s\n", summary.figure.string().c_str());
  if (!results.empty() && !results.front().schemes.empty() &&
      !results.front().schemes.front().replay.figures.empty()) {
    std::printf("Figures, e.g.:\n");
    for (const SchemeResult& sr : results.front().schemes) {
      for (const auto& f : sr.replay.figures) std::printf("  %s\n", f.string().c_str());
    }
  }
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto opt = std::make_shared<SimulateOptions>();
  CLI::App* sub = app.add_subcommand("simulate",
                                     "Run a simulation scenario: closed-loop robot, forces and "
                                     "sensors, then every estimator scheme "
                                     "replayed on the log it wrote (docs/simulation.md)");
  sub->add_option("scenario", opt->scenario, "Scenario file (YAML)")
      ->required()
      ->type_name("SCENARIO.yaml");
  sub->add_option("--out", opt->out, "Output directory (created)")->required()->type_name("DIR");
  sub->add_flag("--no-figures", opt->no_figures, "Do not draw figures (no gnuplot needed)");
  add_jobs_option(*sub, opt->jobs, "seeds simulated, then (seed, scheme) replays,");
  add_figure_format_option(*sub, opt->figure_format);
  add_package_path_option(*sub, opt->package_path);
  add_lock_option(*sub, opt->lock);
  add_chain_options(*sub, opt->root_body, opt->tip_body);
  sub->footer(help_footer(
      {{"extwrench simulate scenarios/paper.yaml --out results/paper",
        "the paper's experiment (Section IV): the closed loop, then every estimator scheme on its "
        "log; metrics and figures"},
       {"extwrench simulate scenarios/paper_free_motion.yaml --out results/free --no-figures",
        "a contact-free motion logged as a real arm logs it (friction, offsets, noise): the log "
        "to rehearse `extwrench calibrate` on"}},
      "docs/simulation.md (scenario files), docs/cli.md (outputs), docs/mujoco.md (engine: "
      "mujoco)"));
  sub->callback([opt]() { run_simulate(*opt); });
}

}  // namespace extwrench::cli
