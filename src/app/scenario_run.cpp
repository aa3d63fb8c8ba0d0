#include "extwrench/app/scenario_run.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "extwrench/app/jobs.hpp"
#include "extwrench/app/joint_range.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/isolation.hpp"
#include "extwrench/geometry/ray.hpp"
#include "extwrench/io/csv.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/text_quoting.hpp"
#include "extwrench/io/urdf_writer.hpp"
#include "extwrench/sim/perturb.hpp"
#include "log_columns.hpp"
#include "progress.hpp"
#include "summary_figure.hpp"

namespace extwrench {
namespace {

// A scheme's configuration error, named at the scheme in the scenario: the configuration file it
// refers to is one the run writes (or would write), which the user never saw, so its name and
// line are dropped; the key path (observer.gain) is the scheme's own.
Error scheme_error(const Scenario& s, const SchemeSpec& scheme,
                   const std::filesystem::path& written, const Error& e) {
  std::string what = e.what();
  const std::string file = written.string() + ":";
  if (what.rfind(file, 0) == 0) {
    if (const auto colon = what.find(": ", file.size()); colon != std::string::npos)
      what.erase(0, colon + 2);
  }
  return Error(s.source.string() + ":" + std::to_string(scheme.line) + ": scheme '" + scheme.name +
               "': " + what);
}

// Every scheme checked before anything is written: its configuration as it will be written,
// with the scenario's own robot in place of the seed's perturbed copy (same links and joints).
void check_schemes(const Scenario& s, const std::filesystem::path& first_dir) {
  const std::string robot = std::filesystem::absolute(s.robot_path).lexically_normal().string();
  const std::string quoted = double_quoted(robot);
  for (const SchemeSpec& scheme : s.schemes) {
    std::string text = scheme_config_yaml(s, scheme);
    const std::string kRobot = "robot: ../model_estimator.urdf\n";
    if (const auto at = text.find(kRobot); at != std::string::npos)
      text.replace(at, kRobot.size(), "robot: " + quoted + "\n");
    const std::filesystem::path written = first_dir / scheme.name / "config.yaml";
    try {
      (void)load_estimator_config_string(text, written, s.robot_options);
    } catch (const Error& e) {
      throw scheme_error(s, scheme, written, e);
    }
  }
}

// Every scheme's configuration file, written and read back before the simulation.
std::vector<EstimatorConfig> write_scheme_configs(const Scenario& s,
                                                  const std::filesystem::path& dir,
                                                  OutputFiles& outputs) {
  std::vector<EstimatorConfig> configs;
  for (const SchemeSpec& scheme : s.schemes) {
    outputs.create_directories(dir / scheme.name);
    const std::filesystem::path cfg = dir / scheme.name / "config.yaml";
    outputs.write_text(cfg, scheme_config_yaml(s, scheme));
    try {
      configs.push_back(load_estimator_config(cfg));
    } catch (const Error& e) {
      throw scheme_error(s, scheme, cfg, e);
    }
  }
  return configs;
}

// Where a pusher coming along an applied force's line first meets the arm, against the force's
// own point. The geometry rule (docs/estimator.md) puts the contact there: a point inside a shape
// (on a link's axis, as the paper's own), behind another link or in the air is then estimated on
// another link or at another point than the truth's. Empty when the pusher meets the force's own
// link at the point (within 5 mm) and nothing before it.
std::string push_point_note(const Model& model, const GeometryModel& geometry, const Data& data,
                            const sim::ForceProfile& profile, const ExternalWrench& w,
                            std::size_t index) {
  constexpr double kTolerance = 0.005;  // [m]
  const double norm = w.force_W.norm();
  if (!(norm > 0.0)) return {};
  const Vector3 u = w.force_W / norm;
  double first = std::numeric_limits<double>::infinity(), own = first;
  int first_body = -1;
  for (int b = 0; b < model.num_bodies(); ++b) {
    const auto k = static_cast<std::size_t>(b);
    if (k >= geometry.body_shapes.size() || geometry.body_shapes[k].empty()) continue;
    const SurfacePointResult hit =
        intersect_line_with_body(geometry, b, data.X_WB[k], w.point_W, u, OnMiss::kNothing);
    if (!hit.hit) continue;
    if (b == w.body) own = hit.entry.lambda;
    if (hit.entry.lambda < first) {
      first = hit.entry.lambda;
      first_body = b;
    }
  }
  if (std::abs(own) <= kTolerance && first >= -kTolerance) return {};
  char where[128];
  std::snprintf(where, sizeof where, "forces[%zu] (%s, point (%s, %s, %s))", index,
                profile.frame.c_str(), format_number(profile.point_F.x()).c_str(),
                format_number(profile.point_F.y()).c_str(),
                format_number(profile.point_F.z()).c_str());
  const auto cm = [](double metres) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f cm", 100.0 * std::abs(metres));
    return std::string(text);
  };
  std::string what;
  if (first_body < 0) {
    what = "its line meets no collision shape of the arm";
  } else {
    const std::string& body = model.bodies[static_cast<std::size_t>(first_body)].name;
    what = first < 0.0
               ? "a pusher along the force meets " + body + " " + cm(first) + " before the point" +
                     (first_body == w.body ? " (the point lies inside the link's shape)" : "")
               : "the point lies " + cm(first) + " in front of " + body + "'s surface, in the air";
  }
  return std::string(where) + ": " + what;
}

// The closed-loop simulation of one seed into r.dir/log.csv, with the estimator's (believed)
// model in the controller; counts the samples and tracks the peak of cond(J of O_l) at the true q.
// `push_point_advice`: what follows a push_point_note, naming the schemes that isolate on
// geometry; empty (no such scheme): the applied forces' points are not checked.
void simulate_seed(const Scenario& s, const Model& believed, int singular_body, bool progress_on,
                   const std::string& push_point_advice, OutputFiles& outputs, SeedResult& r) {
  const Model& model = s.robot.model;
  sim::SimulationConfig sc = s.simulation;
  sc.noise_seed = 2 * r.seed + 1;
  sim::ComputedTorqueController controller(believed, s.trajectory, s.gains);
  std::unique_ptr<sim::SampleSource> source;
  if (s.engine == Scenario::Engine::kMujoco) {
    const MujocoEngine engine = mujoco_engine();
    if (engine == nullptr) {
      throw Error(s.source.string() +
                  ": engine: mujoco, but no MuJoCo engine is registered in this program");
    }
    source = engine(s, std::move(controller), sc);
  } else {
    source = std::make_unique<sim::Simulator>(model, std::move(controller), sc);
  }
  sim::SampleSource& simulator = *source;
  LogLayout layout;
  layout.n = model.nq();
  layout.velocity = s.log_velocity;
  layout.force = sc.sensor.type != SensorType::kNone;
  layout.moment = sc.sensor.type == SensorType::kForceTorque;
  layout.truth = true;
  layout.true_tau_ext = true;
  const std::filesystem::path log_path = r.dir / "log.csv";
  LogWriter log(outputs.stage(log_path), layout);
  Sample sample;
  Data data(model);
  const long total = simulator.num_samples();
  const std::string label = "seed " + std::to_string(r.seed);
  detail::ProgressLine progress(progress_on, 256, std::chrono::milliseconds(200), total);
  bool above = false;
  // Each applied force's point is checked once, at its first active sample.
  std::vector<sim::ForceProfile> forces = s.simulation.forces;
  for (sim::ForceProfile& f : forces) f.resolve(model);
  std::vector<bool> pending(forces.size(), !push_point_advice.empty());
  // The simulator does not enforce joint limits: a motion past them is noted (a real arm stops).
  JointRangeCheck joint_range(model, JointRangeCheck::Margin::kNone);
  while (simulator.next(sample)) {
    log.write(sample);
    joint_range.add(sample);
    for (std::size_t k = 0; k < pending.size(); ++k) {
      const sim::ForceProfile& profile = forces[k];
      if (!pending[k] || profile.scale(sample.t) == 0.0) continue;
      pending[k] = false;
      forward_kinematics(model, data, sample.q);
      ExternalWrench w;
      if (!profile.evaluate(sample.t, data, w)) continue;
      const std::string note = push_point_note(model, s.robot.geometry, data, profile, w, k);
      if (!note.empty()) r.notes.push_back(note + push_point_advice);
    }
    if (singular_body > 0) {
      forward_kinematics(model, data, sample.q);
      const double c = jacobian_condition(model, data, singular_body);
      if (c > r.peak_condition) {
        r.peak_condition = c;
        r.peak_time = sample.t;
      }
      // Every crossing, not only the highest: a periodic motion passes the singularity often.
      if (c > s.singularity_threshold) {
        if (!above) r.singular_spans.emplace_back(sample.t, sample.t);
        r.singular_spans.back().second = sample.t;
      }
      above = c > s.singularity_threshold;
    }
    ++r.samples;
    progress.update(r.samples, "%s: simulating", label.c_str());
  }
  progress.done();
  log.close();
  outputs.commit(log_path);
  const auto& excursions = joint_range.excursions();
  for (std::size_t k = 0; k < excursions.size(); ++k) {
    const auto& e = excursions[k];
    if (e.rows == 0) continue;
    const Joint& j = model.joints[k + 1];
    char text[320];
    std::snprintf(text, sizeof text,
                  "q%zu (joint '%s') reaches %.4g at t = %.4g s, %.3g beyond its limits [%g, %g]: "
                  "the simulator does not stop it, a real arm would (trajectory: amplitude, "
                  "offset)",
                  k + 1, j.name.c_str(), e.q, e.t, e.beyond, j.lower, j.upper);
    r.notes.emplace_back(text);
  }
}

// The metric windows: after the residual's transient, and also outside the singularity when the
// scenario excludes one.
std::vector<ReplayWindow> metric_windows(const Scenario& s, const SeedResult& r,
                                         int singular_body) {
  std::vector<ReplayWindow> windows;
  const std::string from = CsvWriter::format(s.metrics_from);
  sim::MetricsWindow after{s.metrics_from, std::numeric_limits<double>::infinity(),
                           s.metrics_exclude};
  windows.push_back(
      {"after_transient", "t >= " + from + " s (after the residual's transient)", after});
  if (s.singularity_half_width > 0.0 && singular_body > 0) {
    sim::MetricsWindow outside = after;
    for (const auto& [a, b] : r.singular_spans)
      outside.exclude.emplace_back(a - s.singularity_half_width, b + s.singularity_half_width);
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "t >= %s s, excluding ±%g s around each of the %zu crossing(s) of cond(J of "
                  "O_l) > %g, l = %s (peak %.4g at t = %.3f s)",
                  from.c_str(), s.singularity_half_width, r.singular_spans.size(),
                  s.singularity_threshold, s.singularity_link.c_str(), r.peak_condition,
                  r.peak_time);
    windows.push_back({"outside_singularity", buf, outside});
  }
  return windows;
}

// A seed between the two phases of a run: its result so far, its schemes' configurations (read
// back from the files written) and the metric windows of its log.
struct SeedJob {
  SeedResult result;
  std::vector<EstimatorConfig> configs;
  std::vector<ReplayWindow> windows;
};

// One scheme replayed on the seed's log, into its own transaction; notes and warnings go to
// `messages` (the job's buffer).
SchemeResult replay_scheme(const Scenario& s, const SeedJob& seed, std::size_t scheme,
                           const RunOptions& options, bool progress, OutputFiles& outputs,
                           std::ostream& messages) {
  const SeedResult& r = seed.result;
  const std::string& name = s.schemes[scheme].name;
  ReplayOptions ro;
  ro.log = r.dir / "log.csv";
  ro.out_dir = r.dir / name;
  ro.name = name;
  ro.config_label = (r.dir / name / "config.yaml").string();
  ro.windows = seed.windows;
  ro.surface_metrics = s.surface_metrics;
  ro.figures = options.figures && s.figures;
  ro.figure_format = options.figure_format;
  ro.desired_trajectory = &s.trajectory;
  ro.warn_joint_range = false;  // the seed's own note says it once
  ro.progress = progress;
  ro.pipelined = replays_pipelined(options.jobs, s.seeds.size() * s.schemes.size());
  ro.warn_ignored_columns = false;
  ro.outputs = &outputs;
  ro.messages = &messages;
  // Straight from the files just written, like `extwrench estimate`: nothing else is shared.
  const EstimatorConfig& cfg = seed.configs[scheme];
  return {name, replay_log(cfg.robot.model, cfg.robot.geometry, cfg.options, ro)};
}

std::filesystem::path seed_dir(const Scenario& s, std::uint64_t seed,
                               const std::filesystem::path& out_dir) {
  return s.seeds.size() == 1 ? out_dir : out_dir / ("seed_" + std::to_string(seed));
}

// Meshes that are not files (an MJCF's: MuJoCo's compiled vertices) written as OBJ files in
// DIR/meshes/, so that model_estimator.urdf names files `extwrench estimate` can read.
GeometryModel geometry_with_mesh_files(const GeometryModel& geometry,
                                       const std::filesystem::path& dir, OutputFiles& outputs) {
  GeometryModel out = geometry;
  std::map<const TriangleMesh*, std::shared_ptr<const TriangleMesh>> written;
  for (CollisionShape& shape : out.shapes) {
    if (shape.type != ShapeType::kMesh || !shape.mesh) continue;
    std::error_code ec;
    if (std::filesystem::is_regular_file(shape.mesh->path, ec)) continue;
    std::shared_ptr<const TriangleMesh>& file_mesh = written[shape.mesh.get()];
    if (!file_mesh) {
      std::string name = "mesh" + std::to_string(written.size()) + "_";
      for (const char c : shape.mesh->path)
        name +=
            (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-') ? c : '_';
      outputs.create_directories(dir / "meshes");
      const std::filesystem::path file = dir / "meshes" / (name + ".obj");
      {
        std::ostringstream obj;
        obj << "# " << shape.mesh->path << " (written by extwrench simulate)\n";
        const auto& v = shape.mesh->vertices;
        for (Eigen::Index i = 0; i < v.cols(); ++i) {
          obj << "v " << format_number(v(0, i)) << ' ' << format_number(v(1, i)) << ' '
              << format_number(v(2, i)) << '\n';
        }
        const auto& f = shape.mesh->triangles;
        for (Eigen::Index i = 0; i < f.cols(); ++i)
          obj << "f " << f(0, i) + 1 << ' ' << f(1, i) + 1 << ' ' << f(2, i) + 1 << '\n';
        outputs.write_text(file, obj.view());
      }
      auto copy = std::make_shared<TriangleMesh>(*shape.mesh);
      copy->path = std::filesystem::absolute(file).string();
      file_mesh = std::move(copy);
    }
    shape.mesh = file_mesh;
    shape.scale = Vector3::Ones();
  }
  return out;
}

// A seed's simulation: its model, configurations and log, and the metric windows they give.
void simulate_job(const Scenario& s, int singular_body, bool progress, OutputFiles& outputs,
                  SeedJob& job) {
  SeedResult& r = job.result;
  outputs.create_directories(r.dir);
  // Two independent streams per seed: the model error and the sensor noise.
  const Model believed = sim::perturb_model(s.robot.model, s.model_error, 2 * r.seed);
  const std::filesystem::path urdf = r.dir / "model_estimator.urdf";
  write_urdf(outputs.stage(urdf), believed,
             geometry_with_mesh_files(s.robot.geometry, r.dir, outputs));
  outputs.commit(urdf);
  job.configs = write_scheme_configs(s, r.dir, outputs);
  std::string names;
  int geometry_schemes = 0;
  for (std::size_t k = 0; k < job.configs.size(); ++k) {
    const EstimatorConfig& c = job.configs[k];
    if (resolved_rule(c.options.isolation, c.robot.geometry) != IsolationRule::kGeometry) continue;
    names += (geometry_schemes++ == 0 ? "'" : ", '") + s.schemes[k].name + "'";
  }
  const std::string advice =
      geometry_schemes == 0
          ? std::string()
          : ". Geometry isolation (scheme" + std::string(geometry_schemes > 1 ? "s " : " ") +
                names +
                ") estimates the contact where a pusher meets the arm, not at the point: put "
                "the point on the link's surface, or set `isolation: residual` in the scheme, "
                "as scenarios/paper.yaml does";
  simulate_seed(s, believed, singular_body, progress, advice, outputs, r);
  job.windows = metric_windows(s, r, singular_body);
}

// Rethrows the lowest failing job's error (the one a serial run would have met first), named
// after its seed (and scheme) when the run has several.
void rethrow_first_failure(const JobOutcomes& outcomes, const std::string& label) {
  const std::size_t i = outcomes.first_failure();
  if (i == outcomes.errors.size()) return;
  if (label.empty()) std::rethrow_exception(outcomes.errors[i]);
  try {
    std::rethrow_exception(outcomes.errors[i]);
  } catch (const Error& e) {
    throw Error(label + ": " + e.what());
  }
}

// The jobs' own transactions (one per job: OutputFiles is not shared between threads), kept
// when the whole run succeeds; rolled back last-made first, so that a scheme's files go before
// the seed directory holding them.
class JobTransactions {
 public:
  JobTransactions() = default;
  JobTransactions(const JobTransactions&) = delete;
  JobTransactions& operator=(const JobTransactions&) = delete;
  ~JobTransactions() {
    while (!all_.empty()) all_.pop_back();
  }
  OutputFiles& add() { return *all_.emplace_back(std::make_unique<OutputFiles>()); }
  void keep() {
    for (auto& o : all_) o->keep();
  }

 private:
  std::vector<std::unique_ptr<OutputFiles>> all_;
};

// Every seed's simulation, then every (seed, scheme) replay, each phase on options.jobs threads.
std::vector<SeedResult> run_jobs_of(const Scenario& s, const std::filesystem::path& out_dir,
                                    const RunOptions& options, int singular_body,
                                    JobTransactions& transactions) {
  const std::size_t n_seeds = s.seeds.size(), n_schemes = s.schemes.size();
  const JobsOptions jobs{.jobs = options.jobs, .stop_after_failure = true};
  // Progress lines of parallel jobs would overwrite one another on a terminal.
  const bool progress = options.progress && options.jobs == 1;
  std::vector<SeedJob> seeds(n_seeds);
  std::vector<OutputFiles*> seed_outputs(n_seeds);
  for (std::size_t i = 0; i < n_seeds; ++i) {
    seeds[i].result.seed = s.seeds[i];
    seeds[i].result.dir = seed_dir(s, s.seeds[i], out_dir);
    seeds[i].result.schemes.resize(n_schemes);
    seed_outputs[i] = &transactions.add();
  }
  const auto seed_label = [&](std::size_t i) {
    return n_seeds > 1 ? "seed " + std::to_string(s.seeds[i]) : std::string();
  };
  const JobOutcomes simulated = run_jobs(
      n_seeds,
      [&](std::size_t i) { simulate_job(s, singular_body, progress, *seed_outputs[i], seeds[i]); },
      jobs);
  if (const std::size_t failed = simulated.first_failure(); failed < n_seeds)
    rethrow_first_failure(simulated, seed_label(failed));
  std::ostream& console = options.messages != nullptr ? *options.messages : std::cerr;
  for (std::size_t i = 0; i < n_seeds; ++i) {
    const std::string label = seed_label(i);
    for (const std::string& note : seeds[i].result.notes)
      console << "extwrench: note: " << (label.empty() ? "" : label + ": ") << note << "\n";
  }

  std::vector<OutputFiles*> replay_outputs(n_seeds * n_schemes);
  std::vector<std::ostringstream> messages(replay_outputs.size());
  for (auto& o : replay_outputs) o = &transactions.add();
  const JobOutcomes replayed = run_jobs(
      replay_outputs.size(),
      [&](std::size_t k) {
        SeedJob& seed = seeds[k / n_schemes];
        seed.result.schemes[k % n_schemes] = replay_scheme(
            s, seed, k % n_schemes, options, progress, *replay_outputs[k], messages[k]);
      },
      jobs, [&](std::size_t k) { console << messages[k].str() << std::flush; });
  const std::size_t failed = replayed.first_failure();
  if (failed < replayed.errors.size()) {
    const std::string label = seed_label(failed / n_schemes);
    rethrow_first_failure(replayed, (label.empty() ? "" : label + ", ") + "scheme '" +
                                        s.schemes[failed % n_schemes].name + "'");
  }
  std::vector<SeedResult> results;
  for (SeedJob& seed : seeds) results.push_back(std::move(seed.result));
  return results;
}

}  // namespace

namespace {

// What an earlier run into the same directory left that this run did not write (a scheme since
// renamed, other seeds, a single-seed log beside seed directories): its estimates would be read
// beside this run's log as if they were of it.
std::vector<std::filesystem::path> earlier_outputs(const Scenario& s,
                                                   const std::filesystem::path& out_dir) {
  namespace fs = std::filesystem;
  std::vector<fs::path> found;
  std::vector<fs::path> seed_dirs;
  for (const std::uint64_t seed : s.seeds) seed_dirs.push_back(seed_dir(s, seed, out_dir));
  const auto is_scheme = [&](const std::string& name) {
    return std::any_of(s.schemes.begin(), s.schemes.end(),
                       [&](const SchemeSpec& scheme) { return scheme.name == name; });
  };
  std::error_code ec;
  for (const fs::path& dir : seed_dirs) {
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const fs::path p = entry.path();
      if (entry.is_directory(ec) && fs::exists(p / "config.yaml", ec) &&
          !is_scheme(p.filename().string()))
        found.push_back(p);
    }
  }
  for (const auto& entry : fs::directory_iterator(out_dir, ec)) {
    const fs::path p = entry.path();
    if (entry.is_directory(ec) && p.filename().string().rfind("seed_", 0) == 0 &&
        std::find(seed_dirs.begin(), seed_dirs.end(), p) == seed_dirs.end())
      found.push_back(p);
  }
  if (s.seeds.size() > 1 && fs::exists(out_dir / "log.csv", ec))
    found.push_back(out_dir / "log.csv");
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace

std::vector<SeedResult> run_scenario(const Scenario& s, const std::filesystem::path& out_dir,
                                     const RunOptions& options, RunSummary* summary) {
  const Model& model = s.robot.model;
  const int singular_body = s.singularity_link.empty() ? -1 : *model.find_body(s.singularity_link);
  if (!s.seeds.empty()) check_schemes(s, seed_dir(s, s.seeds.front(), out_dir));
  if (options.jobs < 1) throw Error("run_scenario: jobs must be at least 1");
  // One transaction for the whole run, made of the jobs' own: a failure in any seed or scheme
  // leaves none of the run's files.
  OutputFiles outputs;
  if (!s.seeds.empty()) outputs.create_directories(out_dir);
  JobTransactions transactions;  // after `outputs`: rolled back before it
  std::vector<SeedResult> results = run_jobs_of(s, out_dir, options, singular_body, transactions);
  if (options.figures && s.figures && results.size() > 1) {
    const auto figure = detail::draw_summary(s, results, out_dir, options.figure_format, outputs);
    if (summary != nullptr && figure) summary->figure = *figure;
  }
  transactions.keep();
  outputs.keep();
  if (const auto earlier = earlier_outputs(s, out_dir); !earlier.empty()) {
    std::ostream& console = options.messages != nullptr ? *options.messages : std::cerr;
    std::string list;
    for (std::size_t i = 0; i < earlier.size() && i < 6; ++i)
      list += (i ? ", " : "") + earlier[i].string();
    if (earlier.size() > 6) list += " and " + std::to_string(earlier.size() - 6) + " more";
    console << "extwrench: note: " << out_dir.string() << " also holds " << list
            << ", left by an earlier run (not a seed or scheme of this scenario): they are not "
               "this run's results; remove them, or give a fresh --out\n";
  }
  return results;
}

}  // namespace extwrench
