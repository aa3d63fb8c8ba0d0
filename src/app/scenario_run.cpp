#include "extwrench/app/scenario_run.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/io/csv.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/io/urdf_writer.hpp"
#include "extwrench/sim/perturb.hpp"

namespace extwrench {
namespace {

class SimProgress {
 public:
  SimProgress(bool on, long total, std::string label)
      : on_(on), total_(total), label_(std::move(label)) {}
  void update(long k) {
    if (!on_ || (k & 255) != 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    std::fprintf(stderr, "\r  %s: simulating %3.0f %%   ", label_.c_str(),
                 100.0 * static_cast<double>(k) / static_cast<double>(total_));
    std::fflush(stderr);
    shown_ = true;
  }
  void done() {
    if (shown_) std::fprintf(stderr, "\r%*s\r", 60, "");
  }

 private:
  bool on_;
  long total_;
  std::string label_;
  std::chrono::steady_clock::time_point last_{};
  bool shown_ = false;
};

}  // namespace

std::vector<SeedResult> run_scenario(const Scenario& s, const std::filesystem::path& out_dir,
                                     const RunOptions& options) {
  std::vector<SeedResult> results;
  const Model& model = s.robot.model;
  const int singular_body = s.singularity_link.empty() ? -1 : *model.find_body(s.singularity_link);
  for (const std::uint64_t seed : s.seeds) {
    SeedResult r;
    r.seed = seed;
    r.dir = s.seeds.size() == 1 ? out_dir : out_dir / ("seed_" + std::to_string(seed));
    std::filesystem::create_directories(r.dir);
    // Two independent streams per seed: the model error and the sensor noise.
    const Model believed = sim::perturb_model(model, s.model_error, 2 * seed);
    write_urdf(r.dir / "model_estimator.urdf", believed, s.robot.geometry);
    // Configurations written and read back first: a bad scheme fails before the simulation.
    std::vector<EstimatorConfig> configs;
    for (const SchemeSpec& scheme : s.schemes) {
      std::filesystem::create_directories(r.dir / scheme.name);
      const std::filesystem::path cfg = r.dir / scheme.name / "config.yaml";
      {
        std::ofstream out(cfg);
        if (!out) throw Error(cfg.string() + ": cannot create the file");
        out << scheme_config_yaml(s, scheme);
      }
      try {
        configs.push_back(load_estimator_config(cfg));
      } catch (const Error& e) {
        throw Error(s.source.string() + ":" + std::to_string(scheme.line) + ": scheme '" +
                    scheme.name + "': " + e.what());
      }
    }

    sim::SimulationConfig sc = s.simulation;
    sc.noise_seed = 2 * seed + 1;
    sim::Simulator simulator(model, sim::ComputedTorqueController(believed, s.trajectory, s.gains),
                             sc);
    LogLayout layout;
    layout.n = model.nq();
    layout.velocity = s.log_velocity;
    layout.force = sc.sensor.type != sim::BaseSensorType::kNone;
    layout.moment = sc.sensor.type == sim::BaseSensorType::kForceTorque;
    layout.truth = true;
    layout.true_tau_ext = true;
    {
      LogWriter log(r.dir / "log.csv", layout);
      sim::Sample sample;
      Data data(model);
      SimProgress progress(options.progress, simulator.num_samples(),
                           "seed " + std::to_string(seed));
      while (simulator.next(sample)) {
        log.write(sample);
        if (singular_body > 0) {
          forward_kinematics(model, data, sample.q);
          const double c = jacobian_condition(model, data, singular_body);
          if (c > r.peak_condition) {
            r.peak_condition = c;
            r.peak_time = sample.t;
          }
        }
        progress.update(++r.samples);
      }
      progress.done();
      log.close();
    }

    std::vector<ReplayWindow> windows;
    const std::string from = CsvWriter::format(s.metrics_from);
    sim::MetricsWindow after{s.metrics_from, std::numeric_limits<double>::infinity(),
                             s.metrics_exclude};
    windows.push_back(
        {"after_transient", "t >= " + from + " s (after the residual's transient)", after});
    if (s.singularity_half_width > 0.0 && singular_body > 0) {
      sim::MetricsWindow outside = after;
      outside.exclude.emplace_back(r.peak_time - s.singularity_half_width,
                                   r.peak_time + s.singularity_half_width);
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    "t >= %s s, excluding ±%g s around the peak of cond(J of O_l), l = %s (%.4g at "
                    "t = %.3f s)",
                    from.c_str(), s.singularity_half_width, s.singularity_link.c_str(),
                    r.peak_condition, r.peak_time);
      windows.push_back({"outside_singularity", buf, outside});
    }
    for (std::size_t i = 0; i < s.schemes.size(); ++i) {
      ReplayOptions ro;
      ro.log = r.dir / "log.csv";
      ro.out_dir = r.dir / s.schemes[i].name;
      ro.name = s.schemes[i].name;
      ro.config_label = (r.dir / s.schemes[i].name / "config.yaml").string();
      ro.windows = windows;
      ro.surface_metrics = s.surface_metrics;
      ro.figures = options.figures && s.figures;
      ro.progress = options.progress;
      ro.warn_ignored_columns = false;
      // Straight from the files just written, like `extwrench estimate`: nothing else is shared.
      const EstimatorConfig& cfg = configs[i];
      r.schemes.push_back(
          {s.schemes[i].name, replay_log(cfg.robot.model, cfg.robot.geometry, cfg.options, ro)});
    }
    results.push_back(std::move(r));
  }
  return results;
}

}  // namespace extwrench
