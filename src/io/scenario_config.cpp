#include "extwrench/io/scenario_config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>

#include "detail/friction_yaml.hpp"
#include "detail/yaml_reader.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;
using io_detail::non_negative;
using io_detail::positive;
using io_detail::Range;
using io_detail::YamlReader;

// Scenario numbers may be inf ("end: inf", a force that never stops).
constexpr NumberRules kScenarioNumber{.infinity = true};

void parse_trajectory(const YamlReader& y, const YAML::Node& node, int n,
                      sim::SinusoidalTrajectory& tr) {
  y.only_keys(node, "trajectory", {"offset", "amplitude", "frequency", "phase", "more_sines"});
  // One sine's amplitude, frequency and phase under `where` (n numbers or one for all).
  const auto sine = [&](const YAML::Node& m, const std::string& where, VectorX& amplitude,
                        VectorX& frequency, VectorX& phase) {
    const auto part = [&](const char* k) {
      return m[k] ? y.vector(m[k], YamlReader::key(where, k), n) : VectorX::Zero(n);
    };
    amplitude = part("amplitude");
    frequency = part("frequency");
    phase = part("phase");
    for (int i = 0; i < n; ++i) {
      if (frequency[i] < 0.0)
        y.fail(m["frequency"], where + ".frequency", "frequencies must be >= 0 [Hz]");
    }
  };
  tr.offset = node["offset"] ? y.vector(node["offset"], "trajectory.offset", n) : VectorX::Zero(n);
  sine(node, "trajectory", tr.amplitude, tr.frequency, tr.phase);
  tr.more_sines.clear();
  if (const YAML::Node more = node["more_sines"]) {
    if (!more.IsSequence()) {
      y.fail(more, "trajectory.more_sines",
             "expected a list of sines ({amplitude, frequency, phase} each)");
    }
    for (std::size_t k = 0; k < more.size(); ++k) {
      const std::string where = "trajectory.more_sines[" + std::to_string(k) + "]";
      y.only_keys(more[k], where, {"amplitude", "frequency", "phase"});
      sim::SineTerm term;
      sine(more[k], where, term.amplitude, term.frequency, term.phase);
      tr.more_sines.push_back(std::move(term));
    }
  }
}

sim::ForceProfile parse_force(const YamlReader& y, const YAML::Node& node, const std::string& k,
                              const Model& model) {
  y.only_keys(node, k,
              {"frame", "link", "axes", "force", "moment", "point", "start", "end", "ramp"});
  sim::ForceProfile f;
  if (node["frame"] && node["link"]) y.fail(node, k, "give either 'frame' or 'link', not both");
  if (!node["frame"] && !node["link"])
    y.fail(node, k, "missing key 'frame' (the frame or link the force acts on)");
  const YAML::Node fr = node["frame"] ? node["frame"] : node["link"];
  f.frame = y.string(fr, k + ".frame");
  if (!model.find_frame(f.frame)) {
    y.fail(fr, k + ".frame", "'" + f.frame + "' is not a frame of robot '" + model.name + "'");
  }
  if (node["axes"]) {
    f.axes = y.one_of(node["axes"], k + ".axes", {"frame", "link", "world"}) == 2
                 ? sim::ForceProfile::Axes::kWorld
                 : sim::ForceProfile::Axes::kFrame;
  }
  if (node["force"]) f.force = y.vector3(node["force"], k + ".force");
  if (node["moment"]) f.moment = y.vector3(node["moment"], k + ".moment");
  if (node["point"]) f.point_F = y.vector3(node["point"], k + ".point");
  if (node["start"]) f.start = y.number_in(node["start"], k + ".start", non_negative());
  if (node["end"]) f.end = y.number(node["end"], k + ".end");
  if (node["ramp"]) f.ramp = y.number_in(node["ramp"], k + ".ramp", non_negative());
  if (!(f.end > f.start)) y.fail(node, k, "end must be after start");
  // The force ramps up over `ramp` s from start and down over `ramp` s before end: a longer ramp
  // than half the window would cap it below the force given, silently.
  if (f.ramp > 0.5 * (f.end - f.start)) {
    y.fail(node["ramp"], k + ".ramp",
           "a ramp of " + format_number(f.ramp) +
               " s up and as long down does not fit between start " + format_number(f.start) +
               " and end " + format_number(f.end) +
               " s: the force would never reach its value (at most half the window, " +
               format_number(0.5 * (f.end - f.start)) + " s)");
  }
  if (f.force.isZero(0.0) && f.moment.isZero(0.0))
    y.fail(node, k, "force and moment are both zero (give force: [fx, fy, fz] in N, or moment)");
  return f;
}

// The simulated base sensor; its pose defaults to the robot's frame 'sensor' on link 0.
void parse_base_sensor(const YamlReader& y, const YAML::Node& b, sim::BaseSensorModel& base) {
  y.only_keys(b, "sensors.base", {"type", "pose", "bias", "force_noise", "moment_noise"});
  if (b["type"]) base.type = y.sensor_type(b["type"], "sensors.base.type");
  if (b["pose"]) base.X_WS = y.pose(b["pose"], "sensors.base.pose");
  if (b["bias"]) base.bias_S = y.vector(b["bias"], "sensors.base.bias", 6);
  if (b["force_noise"])
    base.force_noise_S = y.vector(b["force_noise"], "sensors.base.force_noise", 3);
  if (b["moment_noise"])
    base.moment_noise_S = y.vector(b["moment_noise"], "sensors.base.moment_noise", 3);
  if ((base.force_noise_S.array() < 0).any() || (base.moment_noise_S.array() < 0).any()) {
    y.fail(b, "sensors.base", "noise standard deviations must be >= 0");
  }
}

void parse_encoder(const YamlReader& y, const YAML::Node& e, sim::EncoderModel& encoder) {
  y.only_keys(e, "sensors.encoder", {"resolution", "velocity", "velocity_cutoff"});
  y.set_number_in(e, "sensors.encoder", "resolution", non_negative(), encoder.resolution);
  if (e["velocity"]) {
    encoder.differentiate =
        y.one_of(e["velocity"], "sensors.encoder.velocity", {"exact", "differentiate"}) == 1;
  }
  y.set_number_in(e, "sensors.encoder", "velocity_cutoff", non_negative(), encoder.velocity_cutoff);
  // The step of a quantised position, not a bit count: a 19-bit encoder's is 2π/2¹⁹ ≈ 1.2e-5.
  if (encoder.resolution > 0.1) {
    y.fail(e["resolution"], "sensors.encoder.resolution",
           format_number(encoder.resolution) +
               " is larger than any encoder's step (rad or m per count; a 19-bit encoder's is "
               "2*pi/2^19 = 1.2e-5 rad): give the step, not the number of bits");
  }
  // The low-pass filters the differentiated q̇ only: with exact q̇ it would change nothing.
  if (encoder.velocity_cutoff > 0.0 && !encoder.differentiate) {
    y.fail(e["velocity_cutoff"], "sensors.encoder.velocity_cutoff",
           "filters the differentiated velocity only: set 'velocity: differentiate' (q̇ is "
           "exact here), or remove velocity_cutoff");
  }
}

// sensors.joint_torque: {friction: the configuration's friction mapping, noise}.
void parse_joint_torque(const YamlReader& y, const YAML::Node& j, const Scenario& s,
                        sim::JointTorqueModel& torque) {
  const std::string k = "sensors.joint_torque";
  y.only_keys(j, k, {"friction", "noise"});
  if (s.engine == Scenario::Engine::kMujoco) {
    y.fail(j, k,
           "with the rigid engine only (MuJoCo's joint friction is the MJCF's frictionloss and "
           "damping)");
  }
  if (const YAML::Node f = j["friction"])
    torque.friction = io_detail::read_friction_mapping(y, f, s.robot.model.nq(), k + ".friction");
  if (const YAML::Node noise = j["noise"]) {
    const Range range = non_negative();
    torque.noise = y.vector(noise, k + ".noise", s.robot.model.nq(), &range);
  }
}

void parse_sensors(const YamlReader& y, const YAML::Node& node, Scenario& s) {
  y.only_keys(node, "sensors", {"base", "encoder", "joint_torque", "log_velocity"});
  sim::BaseSensorModel& base = s.simulation.sensor;
  base.type = SensorType::kForceTorque;
  base.X_WS = default_sensor_pose(s.robot.model);  // a "sensor" frame on a moving body: identity
  if (const YAML::Node b = node["base"]) parse_base_sensor(y, b, base);
  if (const YAML::Node e = node["encoder"]) parse_encoder(y, e, s.simulation.encoder);
  if (const YAML::Node j = node["joint_torque"])
    parse_joint_torque(y, j, s, s.simulation.joint_torque);
  if (node["log_velocity"])
    s.log_velocity = y.boolean(node["log_velocity"], "sensors.log_velocity");
}

// metrics.targets: {SCHEME: {force_rms: N, force_rms_outside: N, line_rms: m, right_link: %}};
// the scheme names are checked once the schemes are read (check_targets).
void parse_targets(const YamlReader& y, const YAML::Node& t, Scenario& s) {
  if (!t.IsMap()) y.fail(t, "metrics.targets", "expected a map {scheme: {metric: value}}");
  for (const auto& entry : t) {
    const std::string scheme = y.string(entry.first, "metrics.targets");
    const std::string k = "metrics.targets." + scheme;
    if (!entry.second.IsMap()) y.fail(entry.second, k, "expected a map {metric: value}");
    y.only_keys(entry.second, k, {"force_rms", "force_rms_outside", "line_rms", "right_link"});
    for (const auto& m : entry.second) {
      const std::string metric = y.string(m.first, k);
      const double value = y.number_in(m.second, k + "." + metric, non_negative());
      s.targets.push_back({scheme, metric, value, m.second.Mark().line + 1});
    }
  }
}

void parse_metrics(const YamlReader& y, const YAML::Node& node, Scenario& s) {
  y.only_keys(node, "metrics",
              {"from", "exclude", "exclude_around_singularity", "singularity_link",
               "singularity_threshold", "surface_point", "targets"});
  y.set_number_in(node, "metrics", "from", non_negative(), s.metrics_from);
  if (const YAML::Node ex = node["exclude"]) {
    if (!ex.IsSequence()) y.fail(ex, "metrics.exclude", "expected a list of [from, to] intervals");
    for (std::size_t i = 0; i < ex.size(); ++i) {
      const std::string k = YamlReader::item("metrics.exclude", i);
      const VectorX v = y.vector(ex[i], k, 2);
      if (!(v[0] < v[1])) y.fail(ex[i], k, "expected [from, to] with from < to");
      s.metrics_exclude.emplace_back(v[0], v[1]);
    }
  }
  y.set_number_in(node, "metrics", "exclude_around_singularity", non_negative(),
                  s.singularity_half_width);
  y.set_number_in(node, "metrics", "singularity_threshold", {1, 1e300, true, "> 1"},
                  s.singularity_threshold);
  if (const YAML::Node t = node["targets"]) parse_targets(y, t, s);
  if (node["singularity_link"]) {
    s.singularity_link = y.string(node["singularity_link"], "metrics.singularity_link");
    (void)y.body(s.robot.model, node["singularity_link"], "metrics.singularity_link");
  }
  if (node["surface_point"])
    s.surface_metrics = y.boolean(node["surface_point"], "metrics.surface_point");
}

// The robot file, relative to the scenario.
void parse_robot(const YamlReader& y, const YAML::Node& root, const LoadOptions& robot_options,
                 Scenario& s) {
  if (!root["robot"])
    y.fail(root, "robot", "missing (the robot file, URDF or DH YAML, relative to the scenario)");
  const fs::path robot = y.string(root["robot"], "robot");
  s.robot_path = robot.is_absolute() ? robot : s.source.parent_path() / robot;
  std::error_code ec;
  if (!fs::is_regular_file(s.robot_path, ec))
    y.fail(root["robot"], "robot", "no such file '" + s.robot_path.string() + "'");
  LoadOptions options = robot_options;
  if (root["locked_joints"]) y.locked_joints(root["locked_joints"], "locked_joints", options);
  y.chain(root, options);
  s.robot = load_robot(s.robot_path, options);
  s.robot_options = options;
}

// seed: 3 or seeds: [1, 2, 3].
void parse_seeds(const YamlReader& y, const YAML::Node& root, Scenario& s) {
  if (root["seed"] && root["seeds"])
    y.fail(root["seeds"], "seeds", "give either seed or seeds, not both");
  const YAML::Node sd = root["seed"] ? root["seed"] : root["seeds"];
  if (!sd) return;
  const std::string k = root["seed"] ? "seed" : "seeds";
  const Range seed{0.0, 9.0e15, false, ">= 0"};
  s.seeds.clear();
  if (!sd.IsSequence()) {
    s.seeds.push_back(static_cast<std::uint64_t>(y.integer(sd, k, seed)));
    return;
  }
  if (sd.size() == 0) y.fail(sd, k, "expected at least one seed");
  for (std::size_t i = 0; i < sd.size(); ++i) {
    const auto value = static_cast<std::uint64_t>(y.integer(sd[i], YamlReader::item(k, i), seed));
    // Each seed's run writes DIR/seed_<n>/: the same seed twice would write one directory twice.
    for (std::size_t j = 0; j < i; ++j) {
      if (s.seeds[j] == value)
        y.fail(sd[i], YamlReader::item(k, i),
               std::to_string(value) + " twice (also " + YamlReader::item(k, j) + ")");
    }
    s.seeds.push_back(value);
  }
}

// duration, sample_time, substeps and model_error.
void parse_timing(const YamlReader& y, const YAML::Node& root, Scenario& s) {
  sim::SimulationConfig& sc = s.simulation;
  y.set_number_in(root, "", "duration", positive(), sc.duration);
  y.set_number_in(root, "", "sample_time", positive(), sc.sample_time);
  if (root["substeps"]) {
    sc.substeps =
        static_cast<int>(y.integer(root["substeps"], "substeps", {1, 1000, false, "in [1, 1000]"}));
  }
  if (sc.duration / sc.sample_time > 1e8) {
    y.fail(root["duration"], "duration",
           "more than 1e8 samples: reduce duration or increase sample_time");
  }
  if (root["model_error"]) {
    s.model_error = y.number_in(root["model_error"], "model_error", non_negative());
    if (s.model_error >= 0.5)
      y.fail(root["model_error"], "model_error",
             "expected a fraction in [0, 0.5), e.g. 0.01 for ±1 %");
  }
}

// omega (triple pole, the default 10 rad/s) or kp, kd, ki per joint.
void parse_controller(const YamlReader& y, const YAML::Node& root, int n, Scenario& s) {
  s.gains = sim::pid_gains_triple_pole(n, 10.0);
  s.controller_omega = 10.0;
  const YAML::Node c = root["controller"];
  if (!c) return;
  y.only_keys(c, "controller", {"omega", "kp", "kd", "ki"});
  if (c["omega"] && (c["kp"] || c["kd"] || c["ki"]))
    y.fail(c, "controller", "give omega or kp/kd/ki, not both");
  if (c["omega"]) {
    s.controller_omega = y.number_in(c["omega"], "controller.omega", positive());
    s.gains = sim::pid_gains_triple_pole(n, s.controller_omega);
    return;
  }
  s.controller_omega = 0.0;
  if (c["kp"]) s.gains.kp = y.vector(c["kp"], "controller.kp", n);
  if (c["kd"]) s.gains.kd = y.vector(c["kd"], "controller.kd", n);
  if (c["ki"]) s.gains.ki = y.vector(c["ki"], "controller.ki", n);
  for (const auto* g : {&s.gains.kp, &s.gains.kd, &s.gains.ki}) {
    if ((g->array() < 0).any()) y.fail(c, "controller", "gains must be >= 0");
  }
}

// Without singularity_link, the singularity window follows the first force's body.
void default_singularity_link(const YamlReader& y, const YAML::Node& root, Scenario& s) {
  if (!(s.singularity_half_width > 0.0) || !s.singularity_link.empty()) return;
  if (s.simulation.forces.empty()) {
    y.fail(root["metrics"], "metrics.exclude_around_singularity",
           "needs metrics.singularity_link (there is no force)");
  }
  const Model& model = s.robot.model;
  const int body =
      model.frames[static_cast<std::size_t>(*model.find_frame(s.simulation.forces.front().frame))]
          .body;
  s.singularity_link = model.bodies[static_cast<std::size_t>(body)].name;
}

// Each scheme is an estimator configuration without `robot`, kept as YAML text: it is checked
// in full when run_scenario writes and reads it back.
void parse_schemes(const YamlReader& y, const YAML::Node& root, Scenario& s) {
  const YAML::Node schemes = root["schemes"];
  if (!schemes) y.fail(root, "schemes", "missing (one or more estimator configurations, by name)");
  if (!schemes.IsMap() || schemes.size() == 0)
    y.fail(schemes, "schemes", "expected a mapping name -> estimator configuration");
  y.unique_keys(schemes, "schemes");  // each scheme writes DIR/<name>/
  for (const auto& kv : schemes) {
    const std::string name = kv.first.Scalar();
    const std::string k = "schemes." + name;
    if (name.empty() || name.find_first_of("/\\ .") != std::string::npos) {
      y.fail(kv.first, k, "scheme names become directory names: use letters, digits, '_' or '-'");
    }
    if (!kv.second.IsMap()) y.fail(kv.second, k, "expected an estimator configuration (a mapping)");
    // The scheme's keys go one by one into its config.yaml: a key given twice would be two
    // configurations in one (yaml-cpp keeps both; the estimator reads the first, the copy the
    // last).
    y.unique_keys(kv.second, k);
    if (kv.second["robot"]) {
      y.fail(kv.second["robot"], k + ".robot",
             "schemes use the scenario's perturbed model; remove 'robot'");
    }
    if (kv.second["locked_joints"]) {
      y.fail(kv.second["locked_joints"], k + ".locked_joints",
             "schemes use the scenario's (reduced) model; give locked_joints at the top level");
    }
    const YAML::Node sensor = kv.second["sensor"];
    if (sensor && !sensor.IsMap()) y.fail(sensor, k + ".sensor", "expected a mapping (type: ...)");
    if (!sensor || !sensor["type"]) {
      y.fail(kv.second, k + ".sensor.type", "missing (ft, force or none)");
    }
    // The scheme replays the simulated log: its sensor must be one the simulation measures (else
    // it failed after the whole simulation, on a column of a generated file).
    const SensorType wanted = y.sensor_type(sensor["type"], k + ".sensor.type");
    const SensorType measured = s.simulation.sensor.type;
    if ((wanted == SensorType::kForceTorque && measured != SensorType::kForceTorque) ||
        (wanted == SensorType::kForce && measured == SensorType::kNone)) {
      y.fail(sensor["type"], k + ".sensor.type",
             std::string("the scheme reads a base ") +
                 (wanted == SensorType::kForceTorque ? "F/T sensor" : "force sensor") +
                 " that the simulation does not measure: sensors.base.type is '" +
                 (measured == SensorType::kNone ? "none" : "force") +
                 "' (default ft; give the scheme that sensor, or the simulation this one)");
    }
    // Kept as text and read back when the scheme's config.yaml is written: text that does not
    // read back (a key with control bytes) is refused here, with its line, not there.
    YAML::Emitter out;
    out << kv.second;
    bool reads_back = out.good();
    try {
      if (reads_back) (void)YAML::Load(out.c_str());
    } catch (const YAML::Exception&) {
      reads_back = false;
    }
    if (!reads_back) {
      y.fail(kv.second, k,
             "cannot be written back as YAML (a key or value with control characters or bytes "
             "that are not UTF-8?)");
    }
    s.schemes.push_back({name, out.c_str(), kv.second.Mark().line + 1});
  }
}

// One obstacle of `obstacles:` (engine: mujoco).
Obstacle parse_obstacle(const YamlReader& y, const YAML::Node& node, const std::string& k) {
  y.only_keys(node, k,
              {"name", "type", "pose", "size", "motion", "friction", "solref", "solimp", "condim"});
  Obstacle o;
  o.line = node.Mark().line + 1;
  o.name = y.string(y.required(node, k, "name"), k + ".name");
  if (o.name.find_first_of(" \t\"<>&'") != std::string::npos)
    y.fail(node["name"], k + ".name", "use letters, digits, '_', '-' or '.'");
  o.shape = static_cast<Obstacle::Shape>(
      y.one_of(y.required(node, k, "type"), k + ".type", {"box", "sphere", "capsule"}));
  if (node["pose"]) o.pose = y.pose(node["pose"], k + ".pose");
  const YAML::Node size = y.required(node, k, "size");
  const Range length{0.0, 1e3, true, "in (0, 1000] m"};
  switch (o.shape) {
    case Obstacle::Shape::kBox:
      o.size = y.vector(size, k + ".size", 3, &length);
      break;
    case Obstacle::Shape::kSphere:
      o.size[0] = y.vector(size, k + ".size", 1, &length)[0];
      break;
    case Obstacle::Shape::kCapsule:
      o.size.head<2>() = y.vector(size, k + ".size", 2, &length);
      break;
  }
  if (!(o.size.array() >= 0.0).all() ||
      (o.shape == Obstacle::Shape::kBox ? o.size.minCoeff() : o.size[0]) <= 0.0)
    y.fail(size, k + ".size", "sizes must be > 0 [m]");
  if (const YAML::Node m = node["motion"]) {
    const std::string km = k + ".motion";
    y.only_keys(m, km, {"type", "amplitude", "frequency", "phase", "velocity", "start", "end"});
    const std::size_t type =
        y.one_of(y.required(m, km, "type"), km + ".type", {"fixed", "sinusoidal", "linear"});
    o.motion = static_cast<Obstacle::Motion>(type);
    const auto forbid = [&](std::initializer_list<const char*> keys, const char* what) {
      for (const char* key : keys) {
        if (m[key])
          y.fail(m[key], km + "." + key, std::string("not a key of a ") + what + " motion");
      }
    };
    if (o.motion == Obstacle::Motion::kSinusoidal) {
      forbid({"velocity", "start", "end"}, "sinusoidal");
      o.amplitude = y.vector3(y.required(m, km, "amplitude"), km + ".amplitude");
      o.frequency = y.number_in(y.required(m, km, "frequency"), km + ".frequency",
                                {0.0, 1e3, true, "in (0, 1000] Hz"});
      if (m["phase"])
        o.phase = y.number_in(m["phase"], km + ".phase", {-1e3, 1e3, false, "finite"});
    } else if (o.motion == Obstacle::Motion::kLinear) {
      forbid({"amplitude", "frequency", "phase"}, "linear");
      o.velocity = y.vector3(y.required(m, km, "velocity"), km + ".velocity");
      o.end = std::numeric_limits<double>::infinity();
      if (m["start"]) o.start = y.number_in(m["start"], km + ".start", non_negative());
      if (m["end"]) o.end = y.number(m["end"], km + ".end");
      if (!(o.end > o.start)) y.fail(m, km, "end must be after start");
    } else {
      forbid({"amplitude", "frequency", "phase", "velocity", "start", "end"}, "fixed");
    }
  }
  const Range positive_value{0.0, 1e300, true, "> 0"};
  if (node["friction"]) {
    o.friction = y.vector3(node["friction"], k + ".friction");
    if (!(o.friction.array() >= 0.0).all() || !(o.friction[0] > 0.0))
      y.fail(node["friction"], k + ".friction",
             "expected [sliding > 0, torsional >= 0, rolling >= 0]");
  }
  if (node["solref"]) o.solref = y.vector(node["solref"], k + ".solref", 2, &positive_value);
  if (node["solimp"]) {
    o.solimp = y.vector(node["solimp"], k + ".solimp", 5);
    const VectorX& v = o.solimp;
    if (!(v[0] > 0.0 && v[0] < 1.0 && v[1] > 0.0 && v[1] < 1.0 && v[2] > 0.0 && v[3] > 0.0 &&
          v[3] < 1.0 && v[4] >= 1.0)) {
      y.fail(node["solimp"], k + ".solimp",
             "expected [dmin, dmax, width, midpoint, power]: dmin, dmax, midpoint in (0, 1), "
             "width > 0, power >= 1");
    }
  }
  if (node["condim"]) {
    const auto c = y.integer(node["condim"], k + ".condim", {1, 6, false, "1, 3, 4 or 6"});
    if (c == 2 || c == 5) y.fail(node["condim"], k + ".condim", "expected 1, 3, 4 or 6");
    o.condim = static_cast<int>(c);
  }
  return o;
}

// engine: rigid | mujoco, and the obstacles and <option> attributes of a MuJoCo scene.
void parse_engine(const YamlReader& y, const YAML::Node& root, Scenario& s) {
  if (const YAML::Node e = root["engine"]) {
    s.engine = y.one_of(e, "engine", {"rigid", "mujoco"}) == 1 ? Scenario::Engine::kMujoco
                                                               : Scenario::Engine::kRigid;
    if (s.engine == Scenario::Engine::kMujoco && mujoco_engine() == nullptr) {
      y.fail(e, "engine",
             "'mujoco' needs extwrench built with MuJoCo (Debian's libmujoco-dev) and a program "
             "that registers it (extwrench::mujoco::register_mujoco_engine(); the extwrench "
             "CLI does when it is built with MuJoCo)");
    }
  }
  if (s.engine == Scenario::Engine::kMujoco && root["locked_joints"] &&
      root["locked_joints"].size() > 0) {
    y.fail(root["locked_joints"], "locked_joints",
           "not with engine: mujoco (MuJoCo simulates every joint of the MJCF; give a file "
           "without the joints, e.g. the Panda without its hand)");
  }
  if (const YAML::Node option = root["mujoco_option"]) {
    if (s.engine != Scenario::Engine::kMujoco)
      y.fail(option, "mujoco_option", "an option of MuJoCo's: set 'engine: mujoco'");
    y.only_keys(option, "mujoco_option", {"cone", "impratio"});
    if (option["cone"]) {
      s.mujoco_option.cone = static_cast<MujocoOption::Cone>(
          y.one_of(option["cone"], "mujoco_option.cone", {"pyramidal", "elliptic"}));
    }
    if (option["impratio"]) {
      s.mujoco_option.impratio = y.number_in(option["impratio"], "mujoco_option.impratio",
                                             {0.0, 1e6, true, "in (0, 1e6]"});
    }
  }
  const YAML::Node obstacles = root["obstacles"];
  if (!obstacles) return;
  if (s.engine != Scenario::Engine::kMujoco)
    y.fail(obstacles, "obstacles", "obstacles are simulated by MuJoCo: set 'engine: mujoco'");
  if (!obstacles.IsSequence()) y.fail(obstacles, "obstacles", "expected a list of obstacles");
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const std::string k = YamlReader::item("obstacles", i);
    Obstacle o = parse_obstacle(y, obstacles[i], k);
    for (const Obstacle& other : s.obstacles) {
      if (other.name == o.name) y.fail(obstacles[i]["name"], k + ".name", "'" + o.name + "' twice");
    }
    s.obstacles.push_back(std::move(o));
  }
}

}  // namespace

namespace {

Scenario read_scenario(const std::filesystem::path& path, const LoadOptions& robot_options) {
  const YamlReader y(path.string(), kScenarioNumber);
  const YAML::Node root = io_detail::load_yaml_file(path, "scenario");
  if (!root.IsDefined() || root.IsNull()) throw Error(y.file() + ": the scenario is empty");
  y.only_keys(root, "",
              {"robot",      "locked_joints", "root_body",   "tip_body",  "seed",
               "seeds",      "duration",      "sample_time", "substeps",  "model_error",
               "trajectory", "controller",    "forces",      "sensors",   "metrics",
               "figures",    "schemes",       "engine",      "obstacles", "mujoco_option"});
  Scenario s;
  s.source = path;
  parse_robot(y, root, robot_options, s);
  const Model& model = s.robot.model;
  const int n = model.nq();
  parse_seeds(y, root, s);
  parse_timing(y, root, s);
  parse_engine(y, root, s);
  if (!root["trajectory"])
    y.fail(root, "trajectory", "missing (offset, amplitude, frequency, phase per joint)");
  parse_trajectory(y, root["trajectory"], n, s.trajectory);
  parse_controller(y, root, n, s);
  if (const YAML::Node f = root["forces"]) {
    if (!f.IsSequence()) y.fail(f, "forces", "expected a list of forces");
    for (std::size_t i = 0; i < f.size(); ++i)
      s.simulation.forces.push_back(parse_force(y, f[i], YamlReader::item("forces", i), model));
  }
  parse_sensors(y, root["sensors"] ? root["sensors"] : YAML::Node(YAML::NodeType::Map), s);
  if (root["metrics"]) parse_metrics(y, root["metrics"], s);
  default_singularity_link(y, root, s);
  if (root["figures"]) s.figures = y.boolean(root["figures"], "figures");
  parse_schemes(y, root, s);
  for (const MetricTarget& t : s.targets) {
    const bool known = std::any_of(s.schemes.begin(), s.schemes.end(),
                                   [&](const SchemeSpec& x) { return x.name == t.scheme; });
    if (!known) {
      throw Error(y.file() + ":" + std::to_string(t.line) + ": metrics.targets." + t.scheme +
                  ": no scheme of that name");
    }
  }
  return s;
}

}  // namespace

namespace {
std::atomic<MujocoEngine> g_mujoco_engine{nullptr};
}  // namespace

void set_mujoco_engine(MujocoEngine engine) noexcept { g_mujoco_engine.store(engine); }

MujocoEngine mujoco_engine() noexcept { return g_mujoco_engine.load(); }

Vector3 Obstacle::position(double t) const {
  switch (motion) {
    case Motion::kSinusoidal:
      return pose.translation +
             amplitude * std::sin(2.0 * std::numbers::pi * frequency * t + phase);
    case Motion::kLinear:
      return pose.translation + velocity * std::clamp(t - start, 0.0, end - start);
    case Motion::kFixed:
      break;
  }
  return pose.translation;
}

Scenario load_scenario(const std::filesystem::path& path, const LoadOptions& robot_options) {
  return io_detail::at_loader_boundary(path.string(),
                                       [&] { return read_scenario(path, robot_options); });
}

namespace {

std::string pose_yaml(const Pose& X) {
  const Vector3 rpy = rpy_from_rotation(X.rotation);
  return "{xyz: [" + format_number(X.translation.x()) + ", " + format_number(X.translation.y()) +
         ", " + format_number(X.translation.z()) + "], rpy: [" + format_number(rpy.x()) + ", " +
         format_number(rpy.y()) + ", " + format_number(rpy.z()) + "]}";
}
}  // namespace

std::string scheme_config_yaml(const Scenario& s, const SchemeSpec& scheme) {
  const std::string label = s.source.string() + ": scheme '" + scheme.name + "'";
  YAML::Node node;
  try {
    node = YAML::Load(scheme.yaml);
  } catch (const YAML::Exception& e) {
    throw Error(label + ": not YAML: " + e.what());
  }
  if (!node.IsMap()) throw Error(label + ": expected an estimator configuration (a mapping)");
  YAML::Node out(YAML::NodeType::Map);
  out["robot"] = "../model_estimator.urdf";
  const Vector3& g = s.robot.model.gravity;
  out["gravity"] = YAML::Load("[" + format_number(g.x()) + ", " + format_number(g.y()) + ", " +
                              format_number(g.z()) + "]");
  for (const auto& kv : node) out[kv.first.Scalar()] = kv.second;
  // The scheme is written into DIR/<scheme>/ (or DIR/seed_<k>/<scheme>/): a calibration file
  // given relative to the scenario, as a user writes it, is written as an absolute path.
  if (const YAML::Node c = out["calibration"]; c && c.IsScalar()) {
    const std::filesystem::path rel(c.Scalar());
    if (!rel.empty() && rel.is_relative())
      out["calibration"] =
          std::filesystem::absolute(s.source.parent_path() / rel).lexically_normal().string();
  }
  if (!out["sensor"].IsMap()) throw Error(label + ": sensor: expected a mapping (type: ...)");
  if (out["sensor"]["type"].Scalar() != "none" && !out["sensor"]["pose"] &&
      !out["sensor"]["frame"]) {
    out["sensor"]["pose"] = YAML::Load(pose_yaml(s.simulation.sensor.X_WS));
  }
  YAML::Emitter e;
  e << out;
  return std::string("# Written by extwrench simulate from ") + s.source.filename().string() +
         ", scheme '" + scheme.name +
         "'.\n# Replay: extwrench estimate --config config.yaml --log ../log.csv --out DIR\n" +
         e.c_str() + "\n";
}

}  // namespace extwrench
