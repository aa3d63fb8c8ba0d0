#include "extwrench/io/calibration_file.hpp"

#include <sstream>

#include "detail/friction_yaml.hpp"
#include "detail/yaml_reader.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/text_quoting.hpp"

namespace extwrench {
namespace io_detail {

JointFriction read_friction_mapping(const YamlReader& rd, const YAML::Node& f, int n,
                                    const std::string& key) {
  rd.only_keys(f, key,
               {"sign", "viscous", "coulomb", "offset", "smoothing_velocity", "velocity_shift",
                "presliding_displacement"});
  JointFriction jf = JointFriction::none(n);
  const Range coefficient = non_negative();
  const Range speed = positive();
  if (f["sign"]) {
    jf.sign = static_cast<SmoothSign>(
        rd.one_of(f["sign"], key + ".sign", {"saturation", "tanh", "sigmoid", "dahl"}));
  }
  if (f["viscous"]) jf.viscous = rd.vector(f["viscous"], key + ".viscous", n, &coefficient);
  if (f["coulomb"]) jf.coulomb = rd.vector(f["coulomb"], key + ".coulomb", n, &coefficient);
  if (f["offset"]) jf.offset = rd.vector(f["offset"], key + ".offset", n);
  const bool dahl = jf.sign == SmoothSign::kDahl;
  if (const YAML::Node v = f["smoothing_velocity"]) {
    if (dahl) rd.fail(v, key + ".smoothing_velocity", "not used with sign: dahl");
    if (v.IsSequence()) {
      jf.joint_smoothing = rd.vector(v, key + ".smoothing_velocity", n, &speed);
    } else {
      jf.smoothing_velocity = rd.number_in(v, key + ".smoothing_velocity", {0, 1e9, true, "> 0"});
    }
  }
  if (f["velocity_shift"]) {
    if (jf.sign != SmoothSign::kSigmoid)
      rd.fail(f["velocity_shift"], key + ".velocity_shift", "only used with sign: sigmoid");
    jf.velocity_shift = rd.vector(f["velocity_shift"], key + ".velocity_shift", n);
  }
  const YAML::Node presliding = f["presliding_displacement"];
  if (dahl && !presliding) rd.fail(f, key, "sign: dahl needs presliding_displacement [rad | m]");
  if (presliding) {
    if (!dahl) rd.fail(presliding, key + ".presliding_displacement", "only used with sign: dahl");
    jf.presliding = rd.vector(presliding, key + ".presliding_displacement", n, &speed);
  }
  return jf;
}

std::string yaml_list(const VectorX& v) {
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

std::string friction_mapping_yaml(const JointFriction& f) {
  std::ostringstream y;
  y.precision(17);
  y << '{';
  if (f.sign != SmoothSign::kSaturation) y << "sign: " << to_string(f.sign) << ", ";
  y << "viscous: " << yaml_list(f.viscous) << ", coulomb: " << yaml_list(f.coulomb);
  if (f.offset.size() > 0) y << ", offset: " << yaml_list(f.offset);
  if (f.sign == SmoothSign::kDahl) {
    y << ", presliding_displacement: " << yaml_list(f.presliding);
  } else if (f.joint_smoothing.size() > 0) {
    // Always a list: a single number would be read back as the shared smoothing velocity.
    y << ", smoothing_velocity: [";
    for (Eigen::Index i = 0; i < f.joint_smoothing.size(); ++i)
      y << (i ? ", " : "") << f.joint_smoothing[i];
    y << ']';
  } else {
    y << ", smoothing_velocity: " << f.smoothing_velocity;
  }
  if (f.velocity_shift.size() > 0) y << ", velocity_shift: " << yaml_list(f.velocity_shift);
  y << '}';
  return y.str();
}

}  // namespace io_detail

namespace {

using io_detail::yaml_list;

std::string joint_table(const Calibration& c) {
  std::ostringstream y;
  y.precision(6);
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    const JointFitReport& j = c.joints[i];
    y << "    - {joint: " << i + 1 << ", rms_before: " << j.rms_before
      << ", rms_after: " << j.rms_after << ", max_before: " << j.max_before
      << ", max_after: " << j.max_after << ", max_after_t: " << j.max_after_t
      << ", variance_explained: " << j.variance_explained << ", noise_std: " << j.noise_std
      << ", crossing_rate: " << j.crossing_rate << ", condition: " << j.condition
      << ", threshold: " << j.threshold
      << ", threshold_rule: " << (j.threshold_from_max ? "largest_residual" : "gaussian")
      << ", noise_at_rest: " << j.noise_at_rest << ", noise_per_speed: " << j.noise_per_speed
      << ", threshold_constant: " << j.threshold_constant
      << ", threshold_at_rest: " << j.threshold_at_rest
      << ", threshold_per_speed: " << j.threshold_per_speed
      << ", mean_threshold_speed: " << j.mean_threshold_speed
      << ", threshold_form: " << (j.speed_dependent ? "speed" : "constant")
      << ", inertia_correction: " << j.inertia_correction << ", inertia_gain: " << j.inertia_gain
      << "}\n";
  }
  return y.str();
}

std::string holdout_yaml(const HoldoutReport& h) {
  std::ostringstream y;
  y.precision(6);
  const double share = h.samples > 0 ? 100.0 * h.false_alarms / h.samples : 0.0;
  y << "holdout:\n  samples: " << h.samples << "\n  duration: " << h.duration
    << "\n  false_alarm_samples: " << h.false_alarms << "\n  false_alarm_percent: " << share
    << "\n  raw_alarm_samples: " << h.raw_alarms
    << "\n  uncalibrated_false_alarm_samples: " << h.uncalibrated_false_alarms
    << "\n  constant_threshold_false_alarm_samples: " << h.constant_threshold_false_alarms
    << "\n  calibrated_threshold: " << yaml_list(h.calibrated_threshold)
    << "\n  calibrated_per_speed: " << yaml_list(h.calibrated_per_speed)
    << "\n  calibrated_constant_threshold: " << yaml_list(h.calibrated_constant_threshold)
    << "\n  best_constant_threshold_uncalibrated: " << yaml_list(h.best_constant_threshold)
    << "\n  calibrated_max_residual: " << yaml_list(h.calibrated_max_residual)
    << "\n  lever: " << h.lever << "\n  min_force_calibrated: [";
  for (std::size_t l = 1; l < h.min_force_calibrated.size(); ++l)
    y << (l > 1 ? ", " : "") << h.min_force_calibrated[l];
  y << "]\n  min_force_best_constant: [";
  for (std::size_t l = 1; l < h.min_force_constant.size(); ++l)
    y << (l > 1 ? ", " : "") << h.min_force_constant[l];
  y << "]\n  min_force_calibrated_constant_threshold: [";
  for (std::size_t l = 1; l < h.min_force_calibrated_constant.size(); ++l)
    y << (l > 1 ? ", " : "") << h.min_force_calibrated_constant[l];
  y << "]\n  min_force_calibrated_best_constant: [";
  for (std::size_t l = 1; l < h.min_force_calibrated_quiet.size(); ++l)
    y << (l > 1 ? ", " : "") << h.min_force_calibrated_quiet[l];
  y << "]\n";
  return y.str();
}

}  // namespace

std::string calibration_to_yaml(const Calibration& c, const HoldoutReport* holdout) {
  std::ostringstream y;
  y.precision(17);
  y << "# extwrench calibration (docs/calibration.md). Include it from an estimator\n"
    << "# configuration with `calibration: THIS_FILE`.\n";
  y << "calibration: {version: 1, source: " << double_quoted(c.source) << ", t_begin: " << c.t_begin
    << ", t_end: " << c.t_end << ", false_alarms_per_hour: " << c.false_alarms_per_hour << "}\n";
  y << "observer: {gain: " << yaml_list(c.observer_gain);
  if ((c.residual_cutoff.array() > 0.0).any())
    y << ", residual_cutoff: " << yaml_list(c.residual_cutoff);
  if ((c.velocity_cutoff.array() > 0.0).any())
    y << ", velocity_cutoff: " << yaml_list(c.velocity_cutoff);
  if (c.inertia_correction.size() > 0 && !c.inertia_correction.isZero(0.0))
    y << ", inertia_correction: " << yaml_list(c.inertia_correction);
  y << "}\n";
  y << "friction: " << io_detail::friction_mapping_yaml(c.friction) << "\n";
  y << "detection: {tau_min: " << yaml_list(c.tau_threshold);
  if (c.tau_per_speed.size() > 0 && (c.tau_per_speed.array() > 0.0).any())
    y << ", tau_per_speed: " << yaml_list(c.tau_per_speed);
  if (c.sensor_type != SensorType::kNone) y << ", f_min: " << c.force_threshold;
  y << "}\n";
  y << "sensor: {type: " << to_string(c.sensor_type);
  if (c.sensor_type != SensorType::kNone) {
    y << ", bias: [";
    for (int i = 0; i < 6; ++i) y << (i ? ", " : "") << c.sensor_bias_S[i];
    y << "], force_noise_W: [" << c.force_noise_W.x() << ", " << c.force_noise_W.y() << ", "
      << c.force_noise_W.z() << ']';
  }
  y << "}\n";
  if (c.payload.identified) {
    const PayloadReport& p = c.payload;
    y << "payload: {body: " << p.body << ", mass: " << p.mass << ", com: [" << p.com.x() << ", "
      << p.com.y() << ", " << p.com.z() << "], rms_before: " << yaml_list(VectorX(p.rms_before))
      << ", rms_after: " << yaml_list(VectorX(p.rms_after)) << ", condition: " << p.condition
      << ", samples: " << p.samples << "}\n";
  }
  if (c.model_check.joint_rms.size() > 0) {
    const ModelCheck& m = c.model_check;
    y << "model_check:\n  joint_rms: " << yaml_list(m.joint_rms) << '\n';
    if (c.sensor_type != SensorType::kNone) {
      y << "  sensor_rms: " << yaml_list(VectorX(m.sensor_rms))
        << "\n  sensor_mean: " << yaml_list(VectorX(m.sensor_mean)) << '\n';
    }
    y << "  patterns: [";
    for (std::size_t i = 0; i < m.patterns.size(); ++i) {
      const ModelPattern& p = m.patterns[i];
      y << (i ? ",\n    " : "\n    ") << "{kind: " << p.kind << ", joint: " << p.joint
        << ", share: " << p.share << ", message: " << double_quoted(p.message) << '}';
    }
    y << "]\n";
  }
  double worst = 0.0;
  for (const JointFitReport& j : c.joints) worst = std::max(worst, j.condition);
  y << "fit:\n  samples: " << c.samples_used << "\n  condition: " << worst << '\n';
  if (!c.joints.empty()) {
    y << "  joints:\n" << joint_table(c);
  } else if (c.residual_noise.size() > 0) {
    // A calibration read from a file keeps only the report's noise levels: written back, they
    // are what a configuration including the file takes (load_calibration).
    y << "  joints:\n";
    for (Eigen::Index i = 0; i < c.residual_noise.size(); ++i)
      y << "    - {joint: " << i + 1 << ", noise_std: " << c.residual_noise[i] << "}\n";
  }
  y << "  suspect_windows: [";
  for (std::size_t i = 0; i < c.suspect_windows.size(); ++i) {
    const SuspectWindow& w = c.suspect_windows[i];
    y << (i ? ", " : "") << "{t_begin: " << w.t_begin << ", t_end: " << w.t_end
      << ", joint: " << w.joint << ", peak: " << w.peak << '}';
  }
  y << "]\n";
  if (holdout != nullptr) y << holdout_yaml(*holdout);
  y << "warnings: [";
  for (std::size_t i = 0; i < c.warnings.size(); ++i)
    y << (i ? ", " : "") << double_quoted(c.warnings[i]);
  y << "]\n";
  return y.str();
}

Calibration load_calibration(const std::filesystem::path& path, int n) {
  return io_detail::at_loader_boundary(path.string(), [&] {
    const YAML::Node root = io_detail::load_yaml_file(path, "calibration");
    const io_detail::YamlReader rd(path.string());
    if (!root.IsDefined() || !root.IsMap()) rd.fail(root, "(top level)", "empty calibration");
    rd.only_keys(root, "",
                 {"calibration", "observer", "friction", "detection", "sensor", "payload",
                  "model_check", "fit", "holdout", "warnings"});
    Calibration c;
    // The log it came from, as `calibrate` wrote it (the rest of that header is a report).
    const YAML::Node header = root["calibration"];
    c.source = header && header.IsMap() && header["source"] && header["source"].IsScalar()
                   ? header["source"].Scalar()
                   : path.string();
    const io_detail::Range positive = io_detail::positive();
    const io_detail::Range non_negative = io_detail::non_negative(">= 0 [N]");
    const YAML::Node ob = rd.required(root, "", "observer");
    rd.only_keys(ob, "observer",
                 {"gain", "residual_cutoff", "velocity_cutoff", "inertia_correction"});
    c.observer_gain = rd.vector(rd.required(ob, "observer", "gain"), "observer.gain", n, &positive);
    // Absent in files written before the residual filter: none.
    const io_detail::Range cutoff = io_detail::non_negative(">= 0 [Hz] (0: none)");
    c.residual_cutoff = ob["residual_cutoff"] ? rd.vector(ob["residual_cutoff"],
                                                          "observer.residual_cutoff", n, &cutoff)
                                              : VectorX::Zero(n);
    // Absent in files written before the velocity filter, and without one: none.
    c.velocity_cutoff = ob["velocity_cutoff"] ? rd.vector(ob["velocity_cutoff"],
                                                          "observer.velocity_cutoff", n, &cutoff)
                                              : VectorX::Zero(n);
    // Absent where none was fitted (and in files written before it): zero.
    c.inertia_correction = ob["inertia_correction"] ? rd.vector(ob["inertia_correction"],
                                                                "observer.inertia_correction", n)
                                                    : VectorX::Zero(n);
    c.friction =
        io_detail::read_friction_mapping(rd, rd.required(root, "", "friction"), n, "friction");
    const YAML::Node det = rd.required(root, "", "detection");
    rd.only_keys(det, "detection", {"tau_min", "tau_per_speed", "f_min"});
    c.tau_threshold =
        rd.vector(rd.required(det, "detection", "tau_min"), "detection.tau_min", n, &positive);
    // Thresholds that follow |q̇| (absent in files written before them: constant).
    const io_detail::Range per_speed = io_detail::non_negative();
    c.tau_per_speed = det["tau_per_speed"] ? rd.vector(det["tau_per_speed"],
                                                       "detection.tau_per_speed", n, &per_speed)
                                           : VectorX::Zero(n);
    const YAML::Node sensor = rd.required(root, "", "sensor");
    rd.only_keys(sensor, "sensor", {"type", "bias", "force_noise_W"});
    c.sensor_type = rd.sensor_type(rd.required(sensor, "sensor", "type"), "sensor.type");
    if (c.sensor_type != SensorType::kNone) {
      const VectorX bias = rd.vector(rd.required(sensor, "sensor", "bias"), "sensor.bias", 6);
      c.sensor_bias_S = bias;
      if (sensor["force_noise_W"])
        c.force_noise_W =
            rd.vector(sensor["force_noise_W"], "sensor.force_noise_W", 3, &non_negative);
      rd.set_number_in(det, "detection", "f_min", {0, 1e12, true, "> 0 [N]"}, c.force_threshold);
      if (!(c.force_threshold > 0))
        rd.fail(det, "detection.f_min", "missing (required with a sensor)");
    }
    // The residual's noise per joint (fit.joints[i].noise_std; the rest of the report is not read).
    if (const YAML::Node fit = root["fit"]; fit && fit.IsMap() && fit["joints"]) {
      const YAML::Node joints = fit["joints"];
      if (!joints.IsSequence() || static_cast<int>(joints.size()) != n)
        rd.fail(joints, "fit.joints", "expected one entry per joint (" + std::to_string(n) + ")");
      c.residual_noise = VectorX::Zero(n);
      for (std::size_t i = 0; i < joints.size(); ++i) {
        if (joints[i]["noise_std"]) {
          c.residual_noise[static_cast<Eigen::Index>(i)] = rd.number_in(
              joints[i]["noise_std"], "fit.joints.noise_std", {0, 1e12, false, ">= 0 [N m]"});
        }
      }
    }
    if (const YAML::Node p = root["payload"]) {
      rd.only_keys(p, "payload",
                   {"body", "mass", "com", "rms_before", "rms_after", "condition", "samples"});
      c.payload.identified = true;
      c.payload.body =
          static_cast<int>(rd.number_in(rd.required(p, "payload", "body"), "payload.body",
                                        {1, static_cast<double>(n), false, "a link index 1..n"}));
      if (c.payload.body != n) rd.fail(p["body"], "payload.body", "expected the last link");
      c.payload.mass = rd.number_in(rd.required(p, "payload", "mass"), "payload.mass",
                                    {0, 1e9, true, "> 0 [kg]"});
      c.payload.com = rd.vector3(rd.required(p, "payload", "com"), "payload.com");
    }
    return c;
  });
}

}  // namespace extwrench
