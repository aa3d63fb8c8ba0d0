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

namespace extwrench::cli {
namespace {

struct SimulateOptions {
  std::filesystem::path scenario;
  std::filesystem::path out;
  bool no_figures = false;
  std::vector<std::filesystem::path> package_path;
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

void run_simulate(const SimulateOptions& opt) {
  LoadOptions load;
  load.package_path = opt.package_path;
  const Scenario scenario = load_scenario(opt.scenario, load);
  RunOptions run;
  run.figures = !opt.no_figures;
  run.progress = isatty(STDERR_FILENO) != 0;
  const std::vector<SeedResult> results = run_scenario(scenario, opt.out, run);

  std::printf(
      "\nextwrench simulate: %s, %zu seed(s), %.3g s at %.3g ms, dynamic parameters ±%g %%\n",
      opt.scenario.string().c_str(), results.size(), scenario.simulation.duration,
      1e3 * scenario.simulation.sample_time, 100.0 * scenario.model_error);
  const std::string from = cell(scenario.metrics_from, "%g");
  std::printf(
      "Metrics after t = %s s; 'F RMS*' excludes ±%g s around the peak of cond(J of O_l), l = "
      "%s.\n\n",
      from.c_str(), scenario.singularity_half_width,
      scenario.singularity_link.empty() ? "-" : scenario.singularity_link.c_str());
  std::printf("%-12s %6s %10s %9s %9s %10s %10s %9s %7s %9s %12s\n", "scheme", "seed", "F RMS [N]",
              "F max [N]", "F RMS*[N]", "line RMS", "line max", "link [%]", "missed", "false al.",
              "peak cond");
  for (const SchemeSpec& scheme : scenario.schemes) {
    double worst_f = 0.0, worst_f_outside = 0.0, worst_line = 0.0, worst_link = 1.0;
    for (const SeedResult& r : results) {
      for (const SchemeResult& sr : r.schemes) {
        if (sr.name != scheme.name) continue;
        const NamedMetrics* a = window_named(sr.replay, "after_transient");
        const NamedMetrics* b = window_named(sr.replay, "outside_singularity");
        if (!a) continue;
        const sim::Metrics& m = a->metrics;
        std::printf("%-12s %6llu %10s %9s %9s %8s m %8s m %9s %7ld %9ld %12s\n",
                    scheme.name.c_str(), static_cast<unsigned long long>(r.seed),
                    cell(m.force.rms(), "%.3f").c_str(), cell(m.force.max, "%.2f").c_str(),
                    b ? cell(b->metrics.force.rms(), "%.3f").c_str() : "-",
                    cell(m.line.rms(), "%.4f").c_str(),
                    cell(m.line.count ? m.line.max : NAN, "%.4f").c_str(),
                    cell(100.0 * m.isolation_accuracy(), "%.2f").c_str(), m.missed, m.false_alarms,
                    cell(r.peak_condition, "%.3g").c_str());
        worst_f = std::max(worst_f, m.force.rms());
        if (b) worst_f_outside = std::max(worst_f_outside, b->metrics.force.rms());
        if (m.line.count > 0) worst_line = std::max(worst_line, m.line.rms());
        worst_link = std::min(worst_link, m.isolation_accuracy());
      }
    }
    if (results.size() > 1) {
      std::printf("%-12s %6s %10s %9s %9s %8s m %10s %9s\n", scheme.name.c_str(), "worst",
                  cell(worst_f, "%.3f").c_str(), "", cell(worst_f_outside, "%.3f").c_str(),
                  cell(worst_line, "%.4f").c_str(), "", cell(100.0 * worst_link, "%.2f").c_str());
    }
  }
  std::printf(
      "\nOutputs (per seed: log.csv, model_estimator.urdf; per scheme: config.yaml, estimates.csv, "
      "metrics.json, figures):\n");
  for (const SeedResult& r : results) {
    std::printf("  %s\n", r.dir.string().c_str());
  }
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
  add_package_path_option(*sub, opt->package_path);
  sub->callback([opt]() { run_simulate(*opt); });
}

}  // namespace extwrench::cli
