#include "extwrench/io/scenario_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>

#include "extwrench/core/error.hpp"
#include "extwrench/io/csv.hpp"

namespace extwrench {
namespace {

class Yaml {
 public:
  explicit Yaml(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& key,
                         const std::string& what) const {
    std::string where = file_;
    if (node.IsDefined() && node.Mark().line >= 0)
      where += ":" + std::to_string(node.Mark().line + 1);
    throw Error(where + ": " + key + ": " + what);
  }

  void only_keys(const YAML::Node& map, const std::string& prefix,
                 std::initializer_list<const char*> allowed) const {
    if (!map.IsMap()) fail(map, prefix.empty() ? "(top level)" : prefix, "expected a mapping");
    const std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& kv : map) {
      const std::string k = kv.first.Scalar();
      if (ok.count(k) == 0) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(kv.first, key(prefix, k), "unknown key (expected one of: " + list + ")");
      }
    }
  }

  static std::string key(const std::string& prefix, const std::string& k) {
    return prefix.empty() ? k : prefix + "." + k;
  }

  double number(const YAML::Node& node, const std::string& k) const {
    if (!node.IsScalar()) fail(node, k, "expected a number");
    const std::string& s = node.Scalar();
    if (s == ".inf" || s == "inf") return std::numeric_limits<double>::infinity();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
      fail(node, k, "expected a finite number, got '" + s + "'");
    }
    return v;
  }

  double positive(const YAML::Node& node, const std::string& k) const {
    const double v = number(node, k);
    if (!(v > 0.0) || !std::isfinite(v))
      fail(node, k, "expected a positive number, got " + node.Scalar());
    return v;
  }

  double non_negative(const YAML::Node& node, const std::string& k) const {
    const double v = number(node, k);
    if (!(v >= 0.0) || !std::isfinite(v))
      fail(node, k, "expected a number >= 0, got " + node.Scalar());
    return v;
  }

  bool boolean(const YAML::Node& node, const std::string& k) const {
    if (node.IsScalar()) {
      const std::string& s = node.Scalar();
      if (s == "true" || s == "yes") return true;
      if (s == "false" || s == "no") return false;
    }
    fail(node, k, "expected true or false");
  }

  std::string string(const YAML::Node& node, const std::string& k) const {
    if (!node.IsScalar() || node.Scalar().empty()) fail(node, k, "expected a non-empty string");
    return node.Scalar();
  }

  /// A list of n numbers, or one number for all n.
  VectorX vector(const YAML::Node& node, const std::string& k, int n) const {
    if (node.IsScalar()) return VectorX::Constant(n, number(node, k));
    if (!node.IsSequence() || static_cast<int>(node.size()) != n) {
      fail(node, k,
           "expected " + std::to_string(n) + " numbers (or one for all)" +
               (node.IsSequence() ? ", got " + std::to_string(node.size()) : ""));
    }
    VectorX v(n);
    for (int i = 0; i < n; ++i)
      v[i] = number(node[static_cast<std::size_t>(i)], k + "[" + std::to_string(i) + "]");
    return v;
  }

  Vector3 vector3(const YAML::Node& node, const std::string& k) const {
    if (!node.IsSequence() || node.size() != 3) fail(node, k, "expected 3 numbers [x, y, z]");
    return vector(node, k, 3);
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

void parse_trajectory(const Yaml& y, const YAML::Node& node, int n, sim::SinusoidalTrajectory& tr) {
  y.only_keys(node, "trajectory", {"offset", "amplitude", "frequency", "phase"});
  tr.offset = node["offset"] ? y.vector(node["offset"], "trajectory.offset", n) : VectorX::Zero(n);
  tr.amplitude =
      node["amplitude"] ? y.vector(node["amplitude"], "trajectory.amplitude", n) : VectorX::Zero(n);
  tr.frequency =
      node["frequency"] ? y.vector(node["frequency"], "trajectory.frequency", n) : VectorX::Zero(n);
  tr.phase = node["phase"] ? y.vector(node["phase"], "trajectory.phase", n) : VectorX::Zero(n);
  for (int i = 0; i < n; ++i) {
    if (tr.frequency[i] < 0.0)
      y.fail(node["frequency"], "trajectory.frequency", "frequencies must be >= 0 [Hz]");
  }
}

sim::ForceProfile parse_force(const Yaml& y, const YAML::Node& node, const std::string& k,
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
    const std::string a = y.string(node["axes"], k + ".axes");
    if (a == "frame" || a == "link") {
      f.axes = sim::ForceProfile::Axes::kFrame;
    } else if (a == "world") {
      f.axes = sim::ForceProfile::Axes::kWorld;
    } else {
      y.fail(node["axes"], k + ".axes", "expected 'frame' or 'world', got '" + a + "'");
    }
  }
  if (node["force"]) f.force = y.vector3(node["force"], k + ".force");
  if (node["moment"]) f.moment = y.vector3(node["moment"], k + ".moment");
  if (node["point"]) f.point = y.vector3(node["point"], k + ".point");
  if (node["start"]) f.start = y.number(node["start"], k + ".start");
  if (node["end"]) f.end = y.number(node["end"], k + ".end");
  if (node["ramp"]) f.ramp = y.non_negative(node["ramp"], k + ".ramp");
  if (!(f.end > f.start)) y.fail(node, k, "end must be after start");
  return f;
}

void parse_sensors(const Yaml& y, const YAML::Node& node, Scenario& s) {
  y.only_keys(node, "sensors", {"base", "encoder", "log_velocity"});
  sim::BaseSensorModel& base = s.simulation.sensor;
  base.type = sim::BaseSensorType::kForceTorque;
  std::string ignored;
  base.X_RS = Pose::identity();
  if (const auto sf = s.robot.model.find_frame("sensor")) {
    const Frame& f = s.robot.model.frames[static_cast<std::size_t>(*sf)];
    if (f.body == 0) base.X_RS = f.placement;
  }
  if (const YAML::Node b = node["base"]) {
    y.only_keys(b, "sensors.base", {"type", "pose", "bias", "force_noise", "moment_noise"});
    if (b["type"]) {
      const std::string t = y.string(b["type"], "sensors.base.type");
      if (t == "ft") {
        base.type = sim::BaseSensorType::kForceTorque;
      } else if (t == "force") {
        base.type = sim::BaseSensorType::kForce;
      } else if (t == "none") {
        base.type = sim::BaseSensorType::kNone;
      } else {
        y.fail(b["type"], "sensors.base.type", "expected ft, force or none, got '" + t + "'");
      }
    }
    if (const YAML::Node p = b["pose"]) {
      y.only_keys(p, "sensors.base.pose", {"xyz", "rpy"});
      const Vector3 xyz = p["xyz"] ? y.vector3(p["xyz"], "sensors.base.pose.xyz") : Vector3::Zero();
      const Vector3 rpy = p["rpy"] ? y.vector3(p["rpy"], "sensors.base.pose.rpy") : Vector3::Zero();
      base.X_RS = Pose::from_xyz_rpy(xyz, rpy);
    }
    if (b["bias"]) base.bias = y.vector(b["bias"], "sensors.base.bias", 6);
    if (b["force_noise"])
      base.force_noise = y.vector(b["force_noise"], "sensors.base.force_noise", 3);
    if (b["moment_noise"])
      base.moment_noise = y.vector(b["moment_noise"], "sensors.base.moment_noise", 3);
    if ((base.force_noise.array() < 0).any() || (base.moment_noise.array() < 0).any()) {
      y.fail(b, "sensors.base", "noise standard deviations must be >= 0");
    }
  }
  if (const YAML::Node e = node["encoder"]) {
    y.only_keys(e, "sensors.encoder", {"resolution", "velocity", "velocity_cutoff"});
    if (e["resolution"])
      s.simulation.encoder.resolution =
          y.non_negative(e["resolution"], "sensors.encoder.resolution");
    if (e["velocity"]) {
      const std::string v = y.string(e["velocity"], "sensors.encoder.velocity");
      if (v == "exact") {
        s.simulation.encoder.differentiate = false;
      } else if (v == "differentiate") {
        s.simulation.encoder.differentiate = true;
      } else {
        y.fail(e["velocity"], "sensors.encoder.velocity",
               "expected exact or differentiate, got '" + v + "'");
      }
    }
    if (e["velocity_cutoff"]) {
      s.simulation.encoder.velocity_cutoff =
          y.non_negative(e["velocity_cutoff"], "sensors.encoder.velocity_cutoff");
    }
  }
  if (node["log_velocity"])
    s.log_velocity = y.boolean(node["log_velocity"], "sensors.log_velocity");
}

void parse_metrics(const Yaml& y, const YAML::Node& node, Scenario& s) {
  y.only_keys(
      node, "metrics",
      {"from", "exclude", "exclude_around_singularity", "singularity_link", "surface_point"});
  if (node["from"]) s.metrics_from = y.non_negative(node["from"], "metrics.from");
  if (const YAML::Node ex = node["exclude"]) {
    if (!ex.IsSequence()) y.fail(ex, "metrics.exclude", "expected a list of [from, to] intervals");
    for (std::size_t i = 0; i < ex.size(); ++i) {
      const std::string k = "metrics.exclude[" + std::to_string(i) + "]";
      const VectorX v = y.vector(ex[i], k, 2);
      if (!(v[0] < v[1])) y.fail(ex[i], k, "expected [from, to] with from < to");
      s.metrics_exclude.emplace_back(v[0], v[1]);
    }
  }
  if (node["exclude_around_singularity"]) {
    s.singularity_half_width =
        y.non_negative(node["exclude_around_singularity"], "metrics.exclude_around_singularity");
  }
  if (node["singularity_link"]) {
    s.singularity_link = y.string(node["singularity_link"], "metrics.singularity_link");
    if (!s.robot.model.find_body(s.singularity_link)) {
      y.fail(node["singularity_link"], "metrics.singularity_link",
             "'" + s.singularity_link + "' is not a link of the robot");
    }
  }
  if (node["surface_point"])
    s.surface_metrics = y.boolean(node["surface_point"], "metrics.surface_point");
}

}  // namespace

Scenario load_scenario(const std::filesystem::path& path, const LoadOptions& robot_options) {
  const std::string file = path.string();
  Yaml y(file);
  YAML::Node root;
  {
    std::ifstream in(path);
    if (!in) throw Error(file + ": cannot open the scenario file");
    try {
      root = YAML::Load(in);
    } catch (const YAML::Exception& e) {
      throw Error(file + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
    }
  }
  if (!root.IsDefined() || root.IsNull()) throw Error(file + ": the scenario is empty");
  y.only_keys(root, "",
              {"robot", "seed", "seeds", "duration", "sample_time", "substeps", "model_error",
               "trajectory", "controller", "forces", "sensors", "metrics", "figures", "schemes"});
  Scenario s;
  s.source = path;
  if (!root["robot"])
    y.fail(root, "robot", "missing (the robot file, URDF or DH YAML, relative to the scenario)");
  const std::filesystem::path robot = y.string(root["robot"], "robot");
  s.robot_path = robot.is_absolute() ? robot : path.parent_path() / robot;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(s.robot_path, ec)) {
    y.fail(root["robot"], "robot", "no such file '" + s.robot_path.string() + "'");
  }
  s.robot = load_robot(s.robot_path, robot_options);
  const Model& model = s.robot.model;
  const int n = model.nq();

  if (root["seed"] && root["seeds"])
    y.fail(root["seeds"], "seeds", "give either seed or seeds, not both");
  if (const YAML::Node sd = root["seed"] ? root["seed"] : root["seeds"]) {
    const std::string k = root["seed"] ? "seed" : "seeds";
    s.seeds.clear();
    auto one = [&](const YAML::Node& v, const std::string& kk) {
      const double x = y.non_negative(v, kk);
      if (x != std::floor(x) || x > 9.0e15) y.fail(v, kk, "expected a non-negative integer");
      s.seeds.push_back(static_cast<std::uint64_t>(x));
    };
    if (sd.IsSequence()) {
      if (sd.size() == 0) y.fail(sd, k, "expected at least one seed");
      for (std::size_t i = 0; i < sd.size(); ++i) one(sd[i], k + "[" + std::to_string(i) + "]");
    } else {
      one(sd, k);
    }
  }
  if (root["duration"]) s.simulation.duration = y.positive(root["duration"], "duration");
  if (root["sample_time"])
    s.simulation.sample_time = y.positive(root["sample_time"], "sample_time");
  if (root["substeps"]) {
    const double v = y.positive(root["substeps"], "substeps");
    if (v != std::floor(v) || v > 1000)
      y.fail(root["substeps"], "substeps", "expected an integer in [1, 1000]");
    s.simulation.substeps = static_cast<int>(v);
  }
  if (s.simulation.duration / s.simulation.sample_time > 1e8) {
    y.fail(root["duration"], "duration",
           "more than 1e8 samples: reduce duration or increase sample_time");
  }
  if (root["model_error"]) {
    s.model_error = y.non_negative(root["model_error"], "model_error");
    if (s.model_error >= 0.5)
      y.fail(root["model_error"], "model_error",
             "expected a fraction in [0, 0.5), e.g. 0.01 for ±1 %");
  }
  if (!root["trajectory"])
    y.fail(root, "trajectory", "missing (offset, amplitude, frequency, phase per joint)");
  parse_trajectory(y, root["trajectory"], n, s.trajectory);

  s.gains = sim::pid_gains_triple_pole(n, 10.0);
  s.controller_omega = 10.0;
  if (const YAML::Node c = root["controller"]) {
    y.only_keys(c, "controller", {"omega", "kp", "kd", "ki"});
    if (c["omega"] && (c["kp"] || c["kd"] || c["ki"]))
      y.fail(c, "controller", "give omega or kp/kd/ki, not both");
    if (c["omega"]) {
      s.controller_omega = y.positive(c["omega"], "controller.omega");
      s.gains = sim::pid_gains_triple_pole(n, s.controller_omega);
    } else {
      s.controller_omega = 0.0;
      if (c["kp"]) s.gains.kp = y.vector(c["kp"], "controller.kp", n);
      if (c["kd"]) s.gains.kd = y.vector(c["kd"], "controller.kd", n);
      if (c["ki"]) s.gains.ki = y.vector(c["ki"], "controller.ki", n);
      for (const auto* g : {&s.gains.kp, &s.gains.kd, &s.gains.ki}) {
        if ((g->array() < 0).any()) y.fail(c, "controller", "gains must be >= 0");
      }
    }
  }
  if (const YAML::Node f = root["forces"]) {
    if (!f.IsSequence()) y.fail(f, "forces", "expected a list of forces");
    for (std::size_t i = 0; i < f.size(); ++i) {
      s.simulation.forces.push_back(
          parse_force(y, f[i], "forces[" + std::to_string(i) + "]", model));
    }
  }
  parse_sensors(y, root["sensors"] ? root["sensors"] : YAML::Node(YAML::NodeType::Map), s);
  if (root["metrics"]) parse_metrics(y, root["metrics"], s);
  if (s.singularity_half_width > 0.0 && s.singularity_link.empty()) {
    if (s.simulation.forces.empty()) {
      y.fail(root["metrics"], "metrics.exclude_around_singularity",
             "needs metrics.singularity_link (there is no force)");
    }
    const int body =
        model.frames[static_cast<std::size_t>(*model.find_frame(s.simulation.forces.front().frame))]
            .body;
    s.singularity_link = model.bodies[static_cast<std::size_t>(body)].name;
  }
  if (root["figures"]) s.figures = y.boolean(root["figures"], "figures");

  const YAML::Node schemes = root["schemes"];
  if (!schemes) y.fail(root, "schemes", "missing (one or more estimator configurations, by name)");
  if (!schemes.IsMap() || schemes.size() == 0)
    y.fail(schemes, "schemes", "expected a mapping name -> estimator configuration");
  for (const auto& kv : schemes) {
    const std::string name = kv.first.Scalar();
    const std::string k = "schemes." + name;
    if (name.empty() || name.find_first_of("/\\ .") != std::string::npos) {
      y.fail(kv.first, k, "scheme names become directory names: use letters, digits, '_' or '-'");
    }
    if (!kv.second.IsMap()) y.fail(kv.second, k, "expected an estimator configuration (a mapping)");
    if (kv.second["robot"]) {
      y.fail(kv.second["robot"], k + ".robot",
             "schemes use the scenario's perturbed model; remove 'robot'");
    }
    if (!kv.second["sensor"] || !kv.second["sensor"]["type"]) {
      y.fail(kv.second, k + ".sensor.type", "missing (ft, force or none)");
    }
    YAML::Emitter out;
    out << kv.second;
    s.schemes.push_back({name, out.c_str(), kv.second.Mark().line + 1});
  }
  return s;
}

namespace {

std::string pose_yaml(const Pose& X) {
  const Vector3 rpy = rpy_from_rotation(X.rotation);
  return "{xyz: [" + CsvWriter::format(X.translation.x()) + ", " +
         CsvWriter::format(X.translation.y()) + ", " + CsvWriter::format(X.translation.z()) +
         "], rpy: [" + CsvWriter::format(rpy.x()) + ", " + CsvWriter::format(rpy.y()) + ", " +
         CsvWriter::format(rpy.z()) + "]}";
}
}  // namespace

std::string scheme_config_yaml(const Scenario& s, const SchemeSpec& scheme) {
  YAML::Node node = YAML::Load(scheme.yaml);
  YAML::Node out(YAML::NodeType::Map);
  out["robot"] = "../model_estimator.urdf";
  const Vector3& g = s.robot.model.gravity;
  out["gravity"] = YAML::Load("[" + CsvWriter::format(g.x()) + ", " + CsvWriter::format(g.y()) +
                              ", " + CsvWriter::format(g.z()) + "]");
  for (const auto& kv : node) out[kv.first.Scalar()] = kv.second;
  if (out["sensor"]["type"].Scalar() != "none" && !out["sensor"]["pose"]) {
    out["sensor"]["pose"] = YAML::Load(pose_yaml(s.simulation.sensor.X_RS));
  }
  YAML::Emitter e;
  e << out;
  return std::string("# Written by extwrench simulate from ") + s.source.filename().string() +
         ", scheme '" + scheme.name +
         "'.\n# Replay: extwrench estimate --config config.yaml --log ../log.csv --out DIR\n" +
         e.c_str() + "\n";
}

}  // namespace extwrench
