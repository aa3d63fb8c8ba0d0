#include "extwrench/io/estimator_config.hpp"

#include <yaml-cpp/yaml.h>

#include <sstream>

#include "detail/friction_yaml.hpp"
#include "detail/yaml_reader.hpp"
#include "extwrench/calibration/calibration.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/calibration_file.hpp"
#include "extwrench/io/text_quoting.hpp"
#include "extwrench/model/model_builder.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;
using io_detail::positive;
using io_detail::Range;
using io_detail::YamlReader;

constexpr int kDefaultTareSamples = 100;

// sensor.frame: a frame of the model fixed to the root link (a URDF's `ft_sensor_link`), whose
// placement is X_WS; the frames that qualify are listed when the name is not one of them.
Pose sensor_frame_pose(const YamlReader& rd, const YAML::Node& node, const Model& model) {
  const std::string name = rd.string(node, "sensor.frame");
  std::string fixed;
  for (const Frame& f : model.frames)
    if (f.body == 0) fixed += (fixed.empty() ? "" : ", ") + f.name;
  const auto frame = model.find_frame(name);
  if (!frame) {
    rd.fail(node, "sensor.frame",
            "'" + name + "' is not a frame of robot '" + model.name +
                "' (frames on the root link '" + model.bodies[0].name +
                "': " + (fixed.empty() ? "none" : fixed) + ")");
  }
  const Frame& f = model.frames[static_cast<std::size_t>(*frame)];
  if (f.body != 0) {
    rd.fail(node, "sensor.frame",
            "'" + name + "' is on the moving link '" +
                model.bodies[static_cast<std::size_t>(f.body)].name +
                "': a base sensor is under the root link (frames on it: " +
                (fixed.empty() ? "none" : fixed) + ")");
  }
  return f.placement;
}

void read_sensor(const YamlReader& rd, const YAML::Node& sensor, const Model& model,
                 SensorOptions& o) {
  rd.only_keys(sensor, "sensor", {"type", "pose", "frame", "tare", "bias"});
  if (!sensor["type"]) rd.fail(sensor, "sensor.type", "missing (ft | force | none)");
  o.type = rd.sensor_type(sensor["type"], "sensor.type");
  if (sensor["pose"] && sensor["frame"])
    rd.fail(sensor["frame"], "sensor.frame", "give either sensor.pose or sensor.frame, not both");
  if (sensor["pose"]) o.X_WS = rd.pose(sensor["pose"], "sensor.pose");
  if (sensor["frame"]) o.X_WS = sensor_frame_pose(rd, sensor["frame"], model);
  if (sensor["bias"]) o.bias_S = rd.vector(sensor["bias"], "sensor.bias", 6);
  if (const YAML::Node t = sensor["tare"]) {
    if (YamlReader::is_boolean(t)) {
      o.tare_samples = rd.boolean(t, "sensor.tare") ? kDefaultTareSamples : 0;
    } else {
      o.tare_samples = static_cast<int>(
          rd.integer(t, "sensor.tare", {0, 1e9, false, "of samples >= 0 (or true / false)"}));
    }
  }
}

void read_contact(const YamlReader& rd, const YAML::Node& c, const Model& model,
                  ContactOptions& o) {
  rd.only_keys(c, "contact", {"model", "link", "point"});
  const bool known_point =
      c["model"] && rd.one_of(c["model"], "contact.model", {"pure_force", "known_point"}) == 1;
  if (!known_point) {
    o.model = ContactModel::kPureForce;
    if (c["link"] || c["point"]) {
      rd.fail(c["link"] ? c["link"] : c["point"], c["link"] ? "contact.link" : "contact.point",
              "only used with contact.model: known_point");
    }
    return;
  }
  o.model = ContactModel::kKnownPoint;
  if (!c["link"]) rd.fail(c, "contact.link", "missing (required with contact.model: known_point)");
  o.link = rd.body(model, c["link"], "contact.link");
  if (c["point"]) o.point_L = rd.vector3(c["point"], "contact.point");
}

void read_observer(const YamlReader& rd, const YAML::Node& ob, int n, EstimatorOptions& o) {
  rd.only_keys(ob, "observer",
               {"gain", "residual_cutoff", "velocity_cutoff", "inertia_correction"});
  const Range gain = positive();
  if (ob["gain"]) o.observer_gain = rd.vector(ob["gain"], "observer.gain", n, &gain);
  const Range cutoff = io_detail::non_negative(">= 0 [Hz] (0: none)");
  if (ob["residual_cutoff"])
    o.residual_cutoff = rd.vector(ob["residual_cutoff"], "observer.residual_cutoff", n, &cutoff);
  if (ob["velocity_cutoff"])
    o.velocity_cutoff = rd.vector(ob["velocity_cutoff"], "observer.velocity_cutoff", n, &cutoff);
  if (ob["inertia_correction"])
    o.inertia_correction = rd.vector(ob["inertia_correction"], "observer.inertia_correction", n);
}

void read_detection(const YamlReader& rd, const YAML::Node& d, int n, DetectionOptions& o) {
  rd.only_keys(d, "detection",
               {"tau_min", "tau_per_speed", "inertial_margin", "f_min", "release_ratio",
                "min_duration", "sensor_release_duration"});
  const Range tau_min = positive();
  if (d["tau_min"]) o.tau_min = rd.vector(d["tau_min"], "detection.tau_min", n, &tau_min);
  const Range per_speed = io_detail::non_negative(">= 0 [N m s/rad]");
  if (d["tau_per_speed"])
    o.tau_per_speed = rd.vector(d["tau_per_speed"], "detection.tau_per_speed", n, &per_speed);
  const Range margin = io_detail::non_negative(">= 0 (a fraction of the dynamic torque)");
  if (d["inertial_margin"])
    o.inertial_margin = rd.vector(d["inertial_margin"], "detection.inertial_margin", n, &margin);
  rd.set_number_in(d, "detection", "f_min", {0, 1e12, true, "> 0 [N]"}, o.f_min);
  rd.set_number_in(d, "detection", "release_ratio", {0, 1, true, "in (0, 1]"}, o.release_ratio);
  rd.set_number_in(d, "detection", "min_duration", {0, 1e6, false, ">= 0 [s]"}, o.min_duration);
  rd.set_number_in(d, "detection", "sensor_release_duration", {0, 1e6, false, ">= 0 [s]"},
                   o.sensor_release_duration);
}

// Either a route (acceleration: residual) or a mapping {route, cutoff}.
void read_acceleration(const YamlReader& rd, const YAML::Node& a, EstimatorOptions& o) {
  if (a.IsMap()) {
    rd.only_keys(a, "acceleration", {"route", "cutoff"});
    if (!a["route"]) rd.fail(a, "acceleration.route", "missing (residual | differentiation)");
    rd.set_number_in(a, "acceleration", "cutoff", {0, 1e9, true, "> 0 [Hz]"},
                     o.differentiation_cutoff);
  }
  // (a fresh handle: assigning to a YAML::Node would overwrite the node it refers to)
  const YAML::Node route = a.IsMap() ? a["route"] : a;
  const std::size_t r = rd.one_of(route, a.IsMap() ? "acceleration.route" : "acceleration",
                                  {"residual", "differentiation"});
  o.acceleration = r == 0 ? AccelerationRoute::kResidual : AccelerationRoute::kDifferentiation;
}

// "model" (the robot file's), "none", or a mapping {sign, viscous, coulomb, offset,
// smoothing_velocity, velocity_shift} (detail/friction_yaml.hpp).
void read_friction(const YamlReader& rd, const YAML::Node& f, int n, EstimatorOptions& o) {
  if (f.IsScalar()) {
    const std::string s = f.Scalar();
    if (s == "none") {
      o.friction = JointFriction::none(n);
    } else if (s != "model") {
      rd.fail(f, "friction",
              "expected model, none or a mapping {viscous, coulomb, smoothing_velocity}, got '" +
                  s + "'");
    }
    return;
  }
  o.friction = io_detail::read_friction_mapping(rd, f, n, "friction");
}

// The calibration's noise levels where the configuration's uncertainty: sets none: the residual's
// std per joint, and the sensor force's std per world axis taken into S (the diagonal of
// R_WSᵀ diag(σ_W²) R_WS; exact for an aligned sensor). The moment's noise is not measured.
void calibrated_noise(const YAML::Node& root, const Calibration& cal, EstimatorOptions& o) {
  const YAML::Node u = root["uncertainty"];
  if (!(u && u["residual_sigma"]) && cal.residual_noise.size() > 0)
    o.uncertainty.residual_sigma = cal.residual_noise;
  if (!(u && u["sensor_force_sigma"]) && cal.sensor_type != SensorType::kNone) {
    const Matrix3& R = o.sensor.X_WS.rotation;
    const Matrix3 in_S = R.transpose() * cal.force_noise_W.cwiseAbs2().asDiagonal() * R;
    o.uncertainty.sensor_force_sigma = in_S.diagonal().cwiseSqrt();
  }
}

// `calibration: CALIB.yaml` (relative to the configuration): friction, thresholds and sensor
// bias from `extwrench calibrate`. Keys the configuration sets itself (friction,
// detection.tau_min, detection.tau_per_speed, detection.f_min, sensor.tare) win over the
// calibration's; a configuration setting tau_min alone gets constant thresholds. Returns the
// file's path.
fs::path read_calibration(const YamlReader& rd, const YAML::Node& root, const fs::path& source,
                          int n, EstimatorOptions& o) {
  const YAML::Node node = root["calibration"];
  const fs::path rel = rd.string(node, "calibration");
  const fs::path path = rel.is_absolute() ? rel : source.parent_path() / rel;
  Calibration cal;
  try {
    cal = load_calibration(path, n);
  } catch (const Error& e) {
    rd.fail(node, "calibration", std::string("cannot load '") + path.string() + "': " + e.what());
  }
  const VectorX gains = per_joint(o.observer_gain, n);
  if (!gains.isApprox(cal.observer_gain, 1e-12)) {
    rd.fail(node, "calibration",
            "'" + path.string() + "' was made with observer.gain " +
                io_detail::yaml_list(cal.observer_gain) + ", this configuration uses " +
                io_detail::yaml_list(gains) + ": set the same gain or calibrate again");
  }
  // The thresholds hold for the residual filtered as it was at calibration: taken from the file
  // unless set here, and then it must be the same.
  // The same for the velocity filter: the fit saw the filtered q̇.
  const YAML::Node ob = root["observer"];
  const auto same_filter = [&](const char* key, VectorX& configured, const VectorX& calibrated) {
    const VectorX cutoff = per_joint(configured, n);
    if (!(ob && ob[key])) {
      configured = calibrated;
    } else if (cutoff != calibrated) {
      rd.fail(node, "calibration",
              "'" + path.string() + "' was made with observer." + key + " " +
                  io_detail::yaml_list(calibrated) + ", this configuration uses " +
                  io_detail::yaml_list(cutoff) +
                  ": its thresholds are for that filter; set the same cutoff or calibrate again");
    }
  };
  same_filter("residual_cutoff", o.residual_cutoff, cal.residual_cutoff);
  same_filter("velocity_cutoff", o.velocity_cutoff,
              cal.velocity_cutoff.size() > 0 ? cal.velocity_cutoff : VectorX::Zero(n));
  if (cal.sensor_type != o.sensor.type) {
    rd.fail(node, "calibration",
            "'" + path.string() + "' was made for sensor type " +
                std::string(to_string(cal.sensor_type)) + ", this configuration has " +
                std::string(to_string(o.sensor.type)));
  }
  const YAML::Node det = root["detection"];
  if (!root["friction"]) o.friction = cal.friction;
  // δI was fitted with the calibration's friction: taken with it, unless set here.
  if (!root["friction"] && !(ob && ob["inertia_correction"]))
    o.inertia_correction = cal.inertia_correction;  // n values (zero where none was fitted)
  if (!(det && det["tau_min"])) o.detection.tau_min = cal.tau_threshold;
  // The speed term belongs to the calibration's τ_min: taken with it, unless set here.
  if (!(det && (det["tau_min"] || det["tau_per_speed"])))
    o.detection.tau_per_speed = cal.tau_per_speed;
  if (!add_identified_payload(cal, o)) {
    rd.fail(node, "calibration",
            "'" + path.string() +
                "' identified a payload on the last link, this configuration has one on another "
                "link");
  }
  calibrated_noise(root, cal, o);
  if (cal.sensor_type != SensorType::kNone) {
    if (!(det && det["f_min"])) o.detection.f_min = cal.force_threshold;
    if (o.sensor.tare_samples == 0) o.sensor.bias_S = cal.sensor_bias_S;
  }
  return path;
}

// "model" (the robot file's), or one number per joint (or one for all) [kg m^2 | kg]: the
// reflected rotor inertias replace the robot file's (docs/model.md "Armature").
void read_armature(const YamlReader& rd, const YAML::Node& a, Model& model) {
  if (a.IsScalar() && a.Scalar() == "model") return;
  const Range range = io_detail::non_negative(">= 0 [kg m^2 | kg]");
  const VectorX values = rd.vector(a, "armature", model.nq(), &range);
  for (int i = 1; i < model.num_bodies(); ++i)
    model.joints[static_cast<std::size_t>(i)].armature = values[i - 1];
}

void read_payload(const YamlReader& rd, const YAML::Node& p, const Model& model,
                  EstimatorOptions& o) {
  rd.only_keys(p, "payload", {"link", "mass", "com", "inertia"});
  if (!p["link"]) rd.fail(p, "payload.link", "missing");
  if (!p["mass"]) rd.fail(p, "payload.mass", "missing");
  PayloadOptions pl;
  pl.body = rd.body(model, p["link"], "payload.link");
  pl.inertia.mass = rd.number_in(p["mass"], "payload.mass", {0, 1e9, false, ">= 0 [kg]"});
  if (p["com"]) pl.inertia.com = rd.vector3(p["com"], "payload.com");
  if (const YAML::Node in = p["inertia"]) {
    if (!in.IsSequence() || in.size() != 6)
      rd.fail(in, "payload.inertia", "expected [ixx, ixy, ixz, iyy, iyz, izz] [kg m^2]");
    double v[6];
    for (std::size_t i = 0; i < 6; ++i)
      v[i] = rd.number(in[i], YamlReader::item("payload.inertia", i));
    pl.inertia.inertia_com << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
    try {
      validate_inertia(pl.inertia, "payload");
    } catch (const Error& e) {
      rd.fail(in, "payload.inertia", e.what());
    }
  }
  o.payload = pl;
}

// isolation: residual | geometry, or {rule: residual | geometry, tolerance, ambiguity_distance,
// misfit_margin}.
void read_isolation(const YamlReader& rd, const YAML::Node& node, IsolationOptions& o) {
  const auto rule = [&](const YAML::Node& r, const std::string& key) {
    return rd.one_of(r, key, {"residual", "geometry"}) == 0 ? IsolationRule::kResidual
                                                            : IsolationRule::kGeometry;
  };
  if (node.IsScalar()) {
    o.rule = rule(node, "isolation");
    return;
  }
  rd.only_keys(node, "isolation", {"rule", "tolerance", "ambiguity_distance", "misfit_margin"});
  if (node["rule"]) o.rule = rule(node["rule"], "isolation.rule");
  rd.set_number_in(node, "isolation", "tolerance", {0, 1e9, true, "> 0 (x tau_min)"}, o.tolerance);
  rd.set_number_in(node, "isolation", "ambiguity_distance", {0, 1e9, false, ">= 0 [m]"},
                   o.ambiguity_distance);
  rd.set_number_in(node, "isolation", "misfit_margin", {0, 1e9, false, ">= 0"}, o.misfit_margin);
}

// drift: true | false, or {time_constant, max_torque_rate, max_force_rate, max_moment_rate}.
void read_drift(const YamlReader& rd, const YAML::Node& node, std::optional<DriftOptions>& o) {
  if (YamlReader::is_boolean(node)) {
    if (rd.boolean(node, "drift")) o = DriftOptions{};
    return;
  }
  rd.only_keys(node, "drift",
               {"time_constant", "max_torque_rate", "max_force_rate", "max_moment_rate"});
  DriftOptions d;
  rd.set_number_in(node, "drift", "time_constant", {0, 1e9, true, "> 0 [s]"}, d.time_constant);
  rd.set_number_in(node, "drift", "max_torque_rate", {0, 1e9, true, "> 0 [N m/s]"},
                   d.max_torque_rate);
  rd.set_number_in(node, "drift", "max_force_rate", {0, 1e9, true, "> 0 [N/s]"}, d.max_force_rate);
  rd.set_number_in(node, "drift", "max_moment_rate", {0, 1e9, true, "> 0 [N m/s]"},
                   d.max_moment_rate);
  o = d;
}

void read_solver(const YamlReader& rd, const YAML::Node& s, SolverOptions& o) {
  rd.only_keys(s, "solver", {"max_condition", "rank_tolerance"});
  rd.set_number_in(s, "solver", "max_condition", {1, 1e300, true, "> 1"}, o.max_condition);
  rd.set_number_in(s, "solver", "rank_tolerance", {0, 1, true, "in (0, 1)"}, o.rank_tolerance);
}

// uncertainty: {residual_sigma, sensor_force_sigma, sensor_moment_sigma, uncertain_fraction,
// uncertain_sigmas} (docs/config.md#uncertainty); a sigma is one number for all or one per joint
// / sensor axis.
void read_uncertainty(const YamlReader& rd, const YAML::Node& u, int n, UncertaintyOptions& o) {
  rd.only_keys(u, "uncertainty",
               {"residual_sigma", "sensor_force_sigma", "sensor_moment_sigma", "uncertain_fraction",
                "uncertain_sigmas"});
  const Range torque = io_detail::non_negative(">= 0 [N m]");
  const Range force = io_detail::non_negative(">= 0 [N]");
  if (u["residual_sigma"])
    o.residual_sigma = rd.vector(u["residual_sigma"], "uncertainty.residual_sigma", n, &torque);
  if (u["sensor_force_sigma"]) {
    o.sensor_force_sigma =
        rd.vector(u["sensor_force_sigma"], "uncertainty.sensor_force_sigma", 3, &force);
  }
  if (u["sensor_moment_sigma"]) {
    o.sensor_moment_sigma =
        rd.vector(u["sensor_moment_sigma"], "uncertainty.sensor_moment_sigma", 3, &torque);
  }
  rd.set_number_in(u, "uncertainty", "uncertain_fraction", {0, 1e12, true, "> 0"},
                   o.uncertain_fraction);
  rd.set_number_in(u, "uncertainty", "uncertain_sigmas", {0, 1e12, true, "> 0"},
                   o.uncertain_sigmas);
}

// The robot file, relative to the configuration, loaded with the configuration's gravity.
void read_robot(const YamlReader& rd, const YAML::Node& root, const fs::path& source,
                LoadOptions robot_options, EstimatorConfig& cfg) {
  if (!root["robot"])
    rd.fail(root, "robot", "missing (path of the URDF or DH YAML, relative to this file)");
  const fs::path robot_rel = rd.string(root["robot"], "robot");
  cfg.robot_path = robot_rel.is_absolute() ? robot_rel : source.parent_path() / robot_rel;
  if (root["gravity"]) robot_options.gravity = rd.vector3(root["gravity"], "gravity");
  if (root["locked_joints"])
    rd.locked_joints(root["locked_joints"], "locked_joints", robot_options);
  cfg.locked_joints = robot_options.locked_joints;
  rd.chain(root, robot_options);
  cfg.root_body = robot_options.root_body;
  cfg.tip_body = robot_options.tip_body;
  try {
    cfg.robot = load_robot(cfg.robot_path, robot_options);
  } catch (const Error& e) {
    rd.fail(root["robot"], "robot",
            std::string("cannot load '") + cfg.robot_path.string() + "': " + e.what());
  }
}

EstimatorConfig interpret(const YAML::Node& root, const fs::path& source,
                          const LoadOptions& robot_options) {
  const YamlReader rd(source.string());
  if (!root.IsDefined() || root.IsNull()) rd.fail(root, "(top level)", "empty configuration");
  rd.only_keys(root, "",
               {"robot", "locked_joints", "root_body", "tip_body", "gravity", "sensor", "contact",
                "observer", "detection", "acceleration", "friction", "armature", "payload",
                "solver", "isolation", "uncertainty", "calibration", "drift"});
  EstimatorConfig cfg;
  cfg.source = source;
  read_robot(rd, root, source, robot_options, cfg);
  if (root["armature"]) read_armature(rd, root["armature"], cfg.robot.model);
  const Model& model = cfg.robot.model;
  const int n = model.nq();
  EstimatorOptions& o = cfg.options;
  if (!root["sensor"])
    rd.fail(root, "sensor", "missing (needs at least sensor.type: ft | force | none)");
  read_sensor(rd, root["sensor"], model, o.sensor);
  // One rule everywhere (dynamics, simulate): without sensor.pose in the file, the model's 'sensor'
  // frame.
  if (root["sensor"]["pose"]) {
    cfg.sensor_pose_source = "sensor.pose";
  } else if (root["sensor"]["frame"]) {
    cfg.sensor_pose_source = "sensor.frame '" + root["sensor"]["frame"].Scalar() + "'";
  } else {
    o.sensor.X_WS = default_sensor_pose(model);
    cfg.sensor_pose_source = describe_default_sensor_pose(model);
  }
  if (root["contact"]) read_contact(rd, root["contact"], model, o.contact);
  if (root["observer"]) read_observer(rd, root["observer"], n, o);
  if (root["detection"]) read_detection(rd, root["detection"], n, o.detection);
  if (root["acceleration"]) read_acceleration(rd, root["acceleration"], o);
  if (root["friction"]) read_friction(rd, root["friction"], n, o);
  if (root["payload"]) read_payload(rd, root["payload"], model, o);
  if (root["solver"]) read_solver(rd, root["solver"], o.solver);
  if (root["isolation"]) read_isolation(rd, root["isolation"], o.isolation);
  if (root["uncertainty"]) read_uncertainty(rd, root["uncertainty"], n, o.uncertainty);
  if (root["drift"]) read_drift(rd, root["drift"], o.drift);
  if (root["calibration"]) cfg.calibration_path = read_calibration(rd, root, source, n, o);

  // The remaining checks need the whole picture (serial chain, sizes).
  try {
    validate(o, model);
  } catch (const Error& e) {
    throw Error(rd.file() + ": " + e.what());
  }
  return cfg;
}

std::string list3(const Vector3& v) {
  std::ostringstream o;
  o.precision(17);
  o << '[' << v.x() << ", " << v.y() << ", " << v.z() << ']';
  return o.str();
}

}  // namespace

std::string describe_default_sensor_pose(const Model& model) {
  const std::string root =
      "the root link's origin ('" + model.bodies[0].name + "'), aligned with it";
  const auto frame = model.find_frame("sensor");
  if (!frame) return root;
  const Frame& f = model.frames[static_cast<std::size_t>(*frame)];
  if (f.body == 0) return "the model's frame 'sensor'";
  return root + " (the model's frame 'sensor' is on the moving body '" +
         model.bodies[static_cast<std::size_t>(f.body)].name + "', not a base sensor)";
}

EstimatorConfig load_estimator_config(const std::filesystem::path& path,
                                      const LoadOptions& robot_options) {
  return io_detail::at_loader_boundary(path.string(), [&] {
    return interpret(io_detail::load_yaml_file(path, "configuration"), path, robot_options);
  });
}

EstimatorConfig load_estimator_config_string(const std::string& yaml,
                                             const std::filesystem::path& name,
                                             const LoadOptions& robot_options) {
  return io_detail::at_loader_boundary(name.string(), [&] {
    return interpret(io_detail::load_yaml_string(yaml, name.string()), name, robot_options);
  });
}

ContactEstimator make_estimator(const EstimatorConfig& config) {
  return ContactEstimator(config.robot.model, config.robot.geometry, config.options);
}

std::string to_yaml(const EstimatorConfig& config, const std::filesystem::path& directory) {
  const EstimatorOptions& o = config.options;
  const Model& model = config.robot.model;
  std::ostringstream y;
  y.precision(17);
  std::filesystem::path robot = config.robot_path;
  if (!directory.empty()) {
    std::error_code ec;
    const std::filesystem::path rel = std::filesystem::relative(robot, directory, ec);
    if (!ec && !rel.empty()) robot = rel;
  }
  y << "robot: " << yaml_scalar(robot.string()) << '\n';
  if (!config.locked_joints.empty()) {
    y << "locked_joints: {";
    const char* sep = "";
    for (const auto& [name, value] : config.locked_joints) {
      y << sep << yaml_scalar(name) << ": " << value;
      sep = ", ";
    }
    y << "}\n";
  }
  if (!config.root_body.empty()) y << "root_body: " << yaml_scalar(config.root_body) << '\n';
  if (!config.tip_body.empty()) y << "tip_body: " << yaml_scalar(config.tip_body) << '\n';
  y << "gravity: " << list3(model.gravity) << '\n';
  y << "sensor:\n  type: " << to_string(o.sensor.type) << '\n';
  const Vector3 rpy = rpy_from_rotation(o.sensor.X_WS.rotation);
  y << "  pose: {xyz: " << list3(o.sensor.X_WS.translation) << ", rpy: " << list3(rpy) << "}\n";
  y << "  tare: " << o.sensor.tare_samples << '\n';
  if (!o.sensor.bias_S.isZero(0.0))
    y << "  bias: " << io_detail::yaml_list(VectorX(o.sensor.bias_S)) << '\n';
  y << "contact:\n  model: " << to_string(o.contact.model) << '\n';
  if (o.contact.model == ContactModel::kKnownPoint) {
    y << "  link: " << model.bodies[static_cast<std::size_t>(o.contact.link)].name << '\n';
    y << "  point: " << list3(o.contact.point_L) << '\n';
  }
  y << "observer:\n  gain: " << io_detail::yaml_list(o.observer_gain) << '\n';
  if ((o.residual_cutoff.array() > 0.0).any())
    y << "  residual_cutoff: " << io_detail::yaml_list(o.residual_cutoff) << '\n';
  if ((o.velocity_cutoff.array() > 0.0).any())
    y << "  velocity_cutoff: " << io_detail::yaml_list(o.velocity_cutoff) << '\n';
  if (!o.inertia_correction.isZero(0.0))
    y << "  inertia_correction: " << io_detail::yaml_list(o.inertia_correction) << '\n';
  y << "detection:\n  tau_min: " << io_detail::yaml_list(o.detection.tau_min);
  if ((o.detection.tau_per_speed.array() > 0.0).any())
    y << "\n  tau_per_speed: " << io_detail::yaml_list(o.detection.tau_per_speed);
  if ((o.detection.inertial_margin.array() > 0.0).any())
    y << "\n  inertial_margin: " << io_detail::yaml_list(o.detection.inertial_margin);
  y << "\n  f_min: " << o.detection.f_min << "\n  release_ratio: " << o.detection.release_ratio
    << "\n  min_duration: " << o.detection.min_duration
    << "\n  sensor_release_duration: " << o.detection.sensor_release_duration << '\n';
  y << "acceleration: {route: " << to_string(o.acceleration)
    << ", cutoff: " << o.differentiation_cutoff << "}\n";
  if (o.friction) {
    y << "friction: " << io_detail::friction_mapping_yaml(*o.friction) << '\n';
  } else {
    y << "friction: model\n";
  }
  if (model.has_armature()) {
    VectorX armature(model.nq());
    for (int i = 1; i < model.num_bodies(); ++i)
      armature[i - 1] = model.joints[static_cast<std::size_t>(i)].armature;
    y << "armature: " << io_detail::yaml_list(armature) << '\n';
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
  // Written only when set, so that a configuration without it reads back to the same default
  // (geometry when the robot has collision shapes).
  const IsolationOptions defaults;
  const IsolationOptions& iso = o.isolation;
  if (iso.rule || iso.tolerance != defaults.tolerance ||
      iso.ambiguity_distance != defaults.ambiguity_distance ||
      iso.misfit_margin != defaults.misfit_margin) {
    y << "isolation: {";
    if (iso.rule) y << "rule: " << to_string(*iso.rule) << ", ";
    y << "tolerance: " << iso.tolerance << ", ambiguity_distance: " << iso.ambiguity_distance
      << ", misfit_margin: " << iso.misfit_margin << "}\n";
  }
  const UncertaintyOptions& u = o.uncertainty;
  y << "uncertainty:\n  residual_sigma: " << io_detail::yaml_list(u.residual_sigma)
    << "\n  sensor_force_sigma: " << list3(u.sensor_force_sigma)
    << "\n  sensor_moment_sigma: " << list3(u.sensor_moment_sigma)
    << "\n  uncertain_fraction: " << u.uncertain_fraction
    << "\n  uncertain_sigmas: " << u.uncertain_sigmas << '\n';
  if (o.drift) {
    y << "drift: {time_constant: " << o.drift->time_constant
      << ", max_torque_rate: " << o.drift->max_torque_rate
      << ", max_force_rate: " << o.drift->max_force_rate
      << ", max_moment_rate: " << o.drift->max_moment_rate << "}\n";
  }
  return y.str();
}

}  // namespace extwrench
