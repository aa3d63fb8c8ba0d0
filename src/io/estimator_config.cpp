#include "extwrench/io/estimator_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "extwrench/core/error.hpp"
#include "extwrench/model/model_builder.hpp"

namespace extwrench {
namespace {

constexpr int kDefaultTareSamples = 100;

/// Reads typed values out of YAML nodes; every error names file, line and key.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& key,
                         const std::string& what) const {
    std::ostringstream o;
    o << file_;
    if (node.IsDefined() && node.Mark().line >= 0) o << ':' << node.Mark().line + 1;
    o << ": " << key << ": " << what;
    throw Error(o.str());
  }

  /// Throws for keys of `map` outside `allowed`.
  void only_keys(const YAML::Node& map, const std::string& prefix,
                 std::initializer_list<const char*> allowed) const {
    if (!map.IsMap()) fail(map, prefix.empty() ? "(top level)" : prefix, "expected a mapping");
    std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      if (ok.count(k) == 0) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(kv.first, prefix.empty() ? k : prefix + "." + k,
             "unknown key (expected one of: " + list + ")");
      }
    }
  }

  std::string string(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected a string");
    return node.Scalar();
  }

  double number(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected a number");
    const std::string& s = node.Scalar();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
      fail(node, key, "expected a finite number, got '" + s + "'");
    }
    return v;
  }

  double number_in(const YAML::Node& node, const std::string& key, double lo, double hi,
                   bool lo_open, const std::string& range) const {
    const double v = number(node, key);
    if ((lo_open ? !(v > lo) : !(v >= lo)) || !(v <= hi)) {
      fail(node, key, "expected a value " + range + ", got " + node.Scalar());
    }
    return v;
  }

  bool boolean(const YAML::Node& node, const std::string& key, bool& out) const {
    if (!node.IsScalar()) return false;
    const std::string& s = node.Scalar();
    if (s == "true" || s == "True" || s == "yes") return out = true, true;
    if (s == "false" || s == "False" || s == "no") return out = false, true;
    (void)key;
    return false;
  }

  Vector3 vector3(const YAML::Node& node, const std::string& key) const {
    if (!node.IsSequence() || node.size() != 3) fail(node, key, "expected a list of 3 numbers");
    Vector3 v;
    for (int i = 0; i < 3; ++i) v[i] = number(node[i], key + "[" + std::to_string(i) + "]");
    return v;
  }

  /// A number for every joint, or a list of n numbers; each > 0 (or ≥ 0 when `allow_zero`).
  VectorX per_joint(const YAML::Node& node, const std::string& key, int n, bool allow_zero) const {
    auto check = [&](const YAML::Node& nd, const std::string& k) {
      const double v = number(nd, k);
      if (allow_zero ? v < 0.0 : !(v > 0.0))
        fail(nd, k,
             std::string("expected a value ") + (allow_zero ? ">= 0" : "> 0") + ", got " +
                 nd.Scalar());
      return v;
    };
    if (node.IsScalar()) return VectorX::Constant(n, check(node, key));
    if (!node.IsSequence())
      fail(node, key, "expected a number or a list of " + std::to_string(n) + " numbers");
    if (static_cast<int>(node.size()) != n) {
      fail(node, key,
           "expected " + std::to_string(n) + " values (one per joint), got " +
               std::to_string(node.size()));
    }
    VectorX v(n);
    for (int i = 0; i < n; ++i) v[i] = check(node[i], key + "[" + std::to_string(i) + "]");
    return v;
  }

  int body(const Model& model, const YAML::Node& node, const std::string& key) const {
    const std::string name = string(node, key);
    const std::optional<int> b = model.find_body(name);
    if (!b) fail(node, key, "no link named '" + name + "' in robot '" + model.name + "'");
    return *b;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

EstimatorConfig interpret(const YAML::Node& root, const std::filesystem::path& source,
                          LoadOptions robot_options) {
  const Reader rd(source.string());
  if (!root.IsDefined() || root.IsNull()) rd.fail(root, "(top level)", "empty configuration");
  rd.only_keys(root, "",
               {"robot", "gravity", "sensor", "contact", "observer", "detection", "acceleration",
                "friction", "payload", "solver"});
  EstimatorConfig cfg;
  cfg.source = source;
  if (!root["robot"])
    rd.fail(root, "robot", "missing (path of the URDF or DH YAML, relative to this file)");
  const std::filesystem::path robot_rel = rd.string(root["robot"], "robot");
  cfg.robot_path = robot_rel.is_absolute() ? robot_rel : source.parent_path() / robot_rel;
  if (root["gravity"]) robot_options.gravity = rd.vector3(root["gravity"], "gravity");
  try {
    cfg.robot = load_robot(cfg.robot_path, robot_options);
  } catch (const Error& e) {
    rd.fail(root["robot"], "robot",
            std::string("cannot load '") + cfg.robot_path.string() + "': " + e.what());
  }
  const Model& model = cfg.robot.model;
  const int n = model.nq();
  EstimatorOptions& o = cfg.options;

  // sensor
  if (!root["sensor"])
    rd.fail(root, "sensor", "missing (needs at least sensor.type: ft | force | none)");
  const YAML::Node sensor = root["sensor"];
  rd.only_keys(sensor, "sensor", {"type", "pose", "tare"});
  if (!sensor["type"]) rd.fail(sensor, "sensor.type", "missing (ft | force | none)");
  const std::string type = rd.string(sensor["type"], "sensor.type");
  if (type == "ft") {
    o.sensor.type = SensorType::kForceTorque;
  } else if (type == "force") {
    o.sensor.type = SensorType::kForce;
  } else if (type == "none") {
    o.sensor.type = SensorType::kNone;
  } else {
    rd.fail(sensor["type"], "sensor.type", "expected one of ft, force, none, got '" + type + "'");
  }
  if (sensor["pose"]) {
    const YAML::Node pose = sensor["pose"];
    rd.only_keys(pose, "sensor.pose", {"xyz", "rpy"});
    const Vector3 xyz = pose["xyz"] ? rd.vector3(pose["xyz"], "sensor.pose.xyz") : Vector3::Zero();
    const Vector3 rpy = pose["rpy"] ? rd.vector3(pose["rpy"], "sensor.pose.rpy") : Vector3::Zero();
    o.sensor.pose = Pose::from_xyz_rpy(xyz, rpy);
  }
  if (sensor["tare"]) {
    const YAML::Node t = sensor["tare"];
    bool b = false;
    if (rd.boolean(t, "sensor.tare", b)) {
      o.sensor.tare_samples = b ? kDefaultTareSamples : 0;
    } else {
      const double v = rd.number(t, "sensor.tare");
      if (v < 0 || v != std::floor(v) || v > 1e9) {
        rd.fail(t, "sensor.tare",
                "expected true, false or a whole number of samples >= 0, got " + t.Scalar());
      }
      o.sensor.tare_samples = static_cast<int>(v);
    }
  }

  // contact
  if (root["contact"]) {
    const YAML::Node c = root["contact"];
    rd.only_keys(c, "contact", {"model", "link", "point"});
    const std::string m = c["model"] ? rd.string(c["model"], "contact.model") : "pure_force";
    if (m == "pure_force") {
      o.contact.model = ContactModel::kPureForce;
      if (c["link"] || c["point"]) {
        rd.fail(c["link"] ? c["link"] : c["point"], c["link"] ? "contact.link" : "contact.point",
                "only used with contact.model: known_point");
      }
    } else if (m == "known_point") {
      o.contact.model = ContactModel::kKnownPoint;
      if (!c["link"])
        rd.fail(c, "contact.link", "missing (required with contact.model: known_point)");
      o.contact.link = rd.body(model, c["link"], "contact.link");
      if (c["point"]) o.contact.point = rd.vector3(c["point"], "contact.point");
    } else {
      rd.fail(c["model"], "contact.model", "expected pure_force or known_point, got '" + m + "'");
    }
  }

  // observer
  if (root["observer"]) {
    const YAML::Node ob = root["observer"];
    rd.only_keys(ob, "observer", {"gain"});
    if (ob["gain"]) o.observer_gain = rd.per_joint(ob["gain"], "observer.gain", n, false);
  }

  // detection
  if (root["detection"]) {
    const YAML::Node d = root["detection"];
    rd.only_keys(d, "detection", {"tau_min", "f_min", "release_ratio", "min_duration"});
    if (d["tau_min"])
      o.detection.tau_min = rd.per_joint(d["tau_min"], "detection.tau_min", n, false);
    if (d["f_min"])
      o.detection.f_min = rd.number_in(d["f_min"], "detection.f_min", 0, 1e12, true, "> 0 [N]");
    if (d["release_ratio"]) {
      o.detection.release_ratio =
          rd.number_in(d["release_ratio"], "detection.release_ratio", 0, 1, true, "in (0, 1]");
    }
    if (d["min_duration"]) {
      o.detection.min_duration =
          rd.number_in(d["min_duration"], "detection.min_duration", 0, 1e6, false, ">= 0 [s]");
    }
  }

  // acceleration
  if (root["acceleration"]) {
    const YAML::Node a = root["acceleration"];
    if (a.IsMap()) {
      rd.only_keys(a, "acceleration", {"route", "cutoff"});
      if (!a["route"]) rd.fail(a, "acceleration.route", "missing (residual | differentiation)");
      if (a["cutoff"])
        o.differentiation_cutoff =
            rd.number_in(a["cutoff"], "acceleration.cutoff", 0, 1e9, true, "> 0 [Hz]");
    }
    // (a fresh handle: assigning to a YAML::Node would overwrite the node it refers to)
    const YAML::Node route = a.IsMap() ? a["route"] : a;
    const std::string r = rd.string(route, a.IsMap() ? "acceleration.route" : "acceleration");
    if (r == "residual") {
      o.acceleration = AccelerationRoute::kResidual;
    } else if (r == "differentiation") {
      o.acceleration = AccelerationRoute::kDifferentiation;
    } else {
      rd.fail(route, "acceleration", "expected residual or differentiation, got '" + r + "'");
    }
  }

  // friction
  if (root["friction"]) {
    const YAML::Node f = root["friction"];
    if (f.IsScalar()) {
      const std::string s = f.Scalar();
      if (s == "none") {
        o.friction = JointFriction::none(n);
      } else if (s != "model") {
        rd.fail(f, "friction",
                "expected model, none or a mapping {viscous, coulomb, smoothing_velocity}, got '" +
                    s + "'");
      }
    } else {
      rd.only_keys(f, "friction", {"viscous", "coulomb", "smoothing_velocity"});
      JointFriction jf = JointFriction::none(n);
      if (f["viscous"]) jf.viscous = rd.per_joint(f["viscous"], "friction.viscous", n, true);
      if (f["coulomb"]) jf.coulomb = rd.per_joint(f["coulomb"], "friction.coulomb", n, true);
      if (f["smoothing_velocity"]) {
        jf.smoothing_velocity = rd.number_in(f["smoothing_velocity"], "friction.smoothing_velocity",
                                             0, 1e9, true, "> 0");
      }
      o.friction = jf;
    }
  }

  // payload
  if (root["payload"]) {
    const YAML::Node p = root["payload"];
    rd.only_keys(p, "payload", {"link", "mass", "com", "inertia"});
    if (!p["link"]) rd.fail(p, "payload.link", "missing");
    if (!p["mass"]) rd.fail(p, "payload.mass", "missing");
    PayloadOptions pl;
    pl.body = rd.body(model, p["link"], "payload.link");
    pl.inertia.mass = rd.number_in(p["mass"], "payload.mass", 0, 1e9, false, ">= 0 [kg]");
    if (p["com"]) pl.inertia.com = rd.vector3(p["com"], "payload.com");
    if (p["inertia"]) {
      const YAML::Node in = p["inertia"];
      if (!in.IsSequence() || in.size() != 6)
        rd.fail(in, "payload.inertia", "expected [ixx, ixy, ixz, iyy, iyz, izz] [kg m^2]");
      double v[6];
      for (int i = 0; i < 6; ++i)
        v[i] = rd.number(in[i], "payload.inertia[" + std::to_string(i) + "]");
      pl.inertia.inertia_com << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
      try {
        validate_inertia(pl.inertia, "payload");
      } catch (const Error& e) {
        rd.fail(in, "payload.inertia", e.what());
      }
    }
    o.payload = pl;
  }

  // solver
  if (root["solver"]) {
    const YAML::Node s = root["solver"];
    rd.only_keys(s, "solver", {"max_condition", "rank_tolerance"});
    if (s["max_condition"])
      o.solver.max_condition =
          rd.number_in(s["max_condition"], "solver.max_condition", 1, 1e300, true, "> 1");
    if (s["rank_tolerance"]) {
      o.solver.rank_tolerance =
          rd.number_in(s["rank_tolerance"], "solver.rank_tolerance", 0, 1, true, "in (0, 1)");
    }
  }

  // The remaining checks need the whole picture (serial chain, sizes): build once to be sure.
  try {
    const ContactEstimator probe(model, cfg.robot.geometry, o);
  } catch (const Error& e) {
    throw Error(rd.file() + ": " + e.what());
  }
  return cfg;
}

YAML::Node parse(const std::string& text, const std::string& name) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(name + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
}

std::string list(const VectorX& v) {
  std::ostringstream o;
  o.precision(17);
  if (v.size() >= 1 && (v.array() == v[0]).all()) {
    o << v[0];
    return o.str();
  }
  o << '[';
  for (Eigen::Index i = 0; i < v.size(); ++i) o << (i ? ", " : "") << v[i];
  o << ']';
  return o.str();
}

std::string list3(const Vector3& v) {
  std::ostringstream o;
  o.precision(17);
  o << '[' << v.x() << ", " << v.y() << ", " << v.z() << ']';
  return o.str();
}

}  // namespace

EstimatorConfig load_estimator_config(const std::filesystem::path& path,
                                      const LoadOptions& robot_options) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open the configuration file");
  std::stringstream ss;
  ss << in.rdbuf();
  return interpret(parse(ss.str(), path.string()), path, robot_options);
}

EstimatorConfig load_estimator_config_string(const std::string& yaml,
                                             const std::filesystem::path& name,
                                             const LoadOptions& robot_options) {
  return interpret(parse(yaml, name.string()), name, robot_options);
}

std::unique_ptr<ContactEstimator> make_estimator(const EstimatorConfig& config) {
  return std::make_unique<ContactEstimator>(config.robot.model, config.robot.geometry,
                                            config.options);
}

std::string to_yaml(const EstimatorConfig& config, const std::filesystem::path& directory) {
  const EstimatorOptions& o = config.options;
  const Model& model = config.robot.model;
  std::ostringstream y;
  y.precision(17);
  std::filesystem::path robot = config.robot_path;
  std::error_code ec;
  const std::filesystem::path rel = std::filesystem::relative(robot, directory, ec);
  if (!ec && !rel.empty()) robot = rel;
  y << "robot: " << robot.string() << '\n';
  y << "gravity: " << list3(model.gravity) << '\n';
  y << "sensor:\n  type: " << to_string(o.sensor.type) << '\n';
  y << "  pose: {xyz: " << list3(o.sensor.pose.translation)
    << ", rpy: " << list3(rpy_from_rotation(o.sensor.pose.rotation)) << "}\n";
  y << "  tare: " << o.sensor.tare_samples << '\n';
  y << "contact:\n  model: " << to_string(o.contact.model) << '\n';
  if (o.contact.model == ContactModel::kKnownPoint) {
    y << "  link: " << model.bodies[static_cast<std::size_t>(o.contact.link)].name << '\n';
    y << "  point: " << list3(o.contact.point) << '\n';
  }
  y << "observer:\n  gain: " << list(o.observer_gain) << '\n';
  y << "detection:\n  tau_min: " << list(o.detection.tau_min) << "\n  f_min: " << o.detection.f_min
    << "\n  release_ratio: " << o.detection.release_ratio
    << "\n  min_duration: " << o.detection.min_duration << '\n';
  y << "acceleration: {route: " << to_string(o.acceleration)
    << ", cutoff: " << o.differentiation_cutoff << "}\n";
  if (o.friction) {
    y << "friction: {viscous: " << list(o.friction->viscous)
      << ", coulomb: " << list(o.friction->coulomb)
      << ", smoothing_velocity: " << o.friction->smoothing_velocity << "}\n";
  } else {
    y << "friction: model\n";
  }
  if (o.payload) {
    const Inertia& in = o.payload->inertia;
    const Matrix3& I = in.inertia_com;
    y << "payload:\n  link: " << model.bodies[static_cast<std::size_t>(o.payload->body)].name
      << "\n  mass: " << in.mass << "\n  com: " << list3(in.com) << "\n  inertia: [" << I(0, 0)
      << ", " << I(0, 1) << ", " << I(0, 2) << ", " << I(1, 1) << ", " << I(1, 2) << ", " << I(2, 2)
      << "]\n";
  }
  y << "solver: {max_condition: " << o.solver.max_condition
    << ", rank_tolerance: " << o.solver.rank_tolerance << "}\n";
  return y.str();
}

}  // namespace extwrench
