// Calibration on a real robot (issue 10, acceptance 2): the Franka Panda's contact-free
// identification trajectory (../shared/realdata/franka_panda_free_motion), K = 50, fitted on the
// first 60 % and judged on the last 40 %. Skips when ../shared is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "extwrench/calibration/holdout.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/geometry/ray.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/log.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

fs::path panda_dir() {
  return fs::path(EXTWRENCH_SHARED_DIR) / "realdata" / "franka_panda_free_motion";
}

constexpr double kFitFraction = 0.6;
constexpr double kMaxFalseAlarmShare = 0.001;  // acceptance 2: ≤ 0.1 % of the held-out samples
constexpr double kClearMargin = 1.5;  // a push's torque this far over a threshold: detectable
constexpr double kMaxPushForceError = 0.15;  // RMS ‖F̂ − F‖ / RMS ‖F‖ of an observable push
// The residual filter on the proximal joints, whose residual is mostly q̇ noise through K B(q)
// (docs/calibration.md#residual-filter); the wrist's is friction, which the filter cannot help.
constexpr const char* kFilteredObserver = "{gain: 50, residual_cutoff: [20, 20, 20, 20, 0, 0, 0]}";

EstimatorConfig panda_config(const std::string& observer = "{gain: 50}") {
  return load_estimator_config_string("robot: " + (panda_dir() / "panda.urdf").string() +
                                          "\nsensor: {type: none}\nobserver: " + observer + "\n",
                                      panda_dir() / "config.yaml");
}

std::vector<Sample> panda_log(const Model& model) {
  std::vector<Sample> samples;
  LogReader reader(panda_dir() / "log.csv", model);
  Sample s;
  while (reader.next(s)) samples.push_back(s);
  return samples;
}

// The fit part of the log (its first kFitFraction); `first` gets its size.
std::vector<Sample> fit_part(const std::vector<Sample>& samples, std::size_t& first) {
  first = static_cast<std::size_t>(kFitFraction * static_cast<double>(samples.size()));
  return {samples.begin(), samples.begin() + static_cast<long>(first)};
}

// The log, its fit part's size (the first kFitFraction) and the calibration made on that part.
struct HeldOutRun {
  std::vector<Sample> samples;
  std::size_t first = 0;
  Calibration cal;
};
HeldOutRun calibrated_on_fit_part(const EstimatorConfig& cfg) {
  HeldOutRun run;
  run.samples = panda_log(cfg.robot.model);
  run.first = static_cast<std::size_t>(kFitFraction * static_cast<double>(run.samples.size()));
  run.cal = calibrate(
      cfg.robot.model, cfg.options,
      std::vector<Sample>(run.samples.begin(), run.samples.begin() + static_cast<long>(run.first)));
  return run;
}

TEST(CalibrationPanda, HeldOutFreeMotionStaysQuietAndLightTouchesGetDetectable) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig cfg = panda_config();
  const Model& model = cfg.robot.model;
  const std::vector<Sample> samples = panda_log(model);
  ASSERT_GT(samples.size(), 9000u);
  const auto first = static_cast<std::size_t>(kFitFraction * static_cast<double>(samples.size()));
  const std::vector<Sample> fit(samples.begin(), samples.begin() + static_cast<long>(first));
  const Calibration cal = calibrate(model, cfg.options, fit);
  const HoldoutReport rep = validate_holdout(model, cfg.options, cal, samples, first);

  EXPECT_LE(rep.false_alarms, kMaxFalseAlarmShare * rep.samples)
      << rep.false_alarms << " of " << rep.samples;
  // Without calibration the configured defaults alarm on most samples (README of the data).
  EXPECT_GT(rep.uncalibrated_false_alarms, rep.samples / 2);
  for (int i = 0; i < 7; ++i) {
    RecordProperty("threshold_joint" + std::to_string(i + 1),
                   std::to_string(rep.calibrated_threshold[i]) + " vs " +
                       std::to_string(rep.best_constant_threshold[i]));
    EXPECT_LT(cal.joints[static_cast<std::size_t>(i)].rms_after,
              cal.joints[static_cast<std::size_t>(i)].rms_before)
        << "joint " << i + 1;
  }
  // At the smallest constant thresholds that stay quiet on the held-out samples, calibration
  // lowers every joint's level and the force detectable on links 4-7; with the thresholds set
  // for one false alarm per hour (extrapolated from 6 s of data) only the wrist's friction-
  // dominated link 7 gets lower than that oracle (docs/calibration.md, real Panda).
  for (int i = 0; i < 7; ++i)
    EXPECT_LT(rep.calibrated_max_residual[i], rep.best_constant_threshold[i]) << "joint " << i + 1;
  for (std::size_t l = 4; l <= 7; ++l) {
    EXPECT_LT(rep.min_force_calibrated_quiet[l], rep.min_force_constant[l]) << "link " << l;
  }
  EXPECT_LT(rep.min_force_calibrated[7], rep.min_force_constant[7]);
}

// Thresholds that follow |q̇| (ThresholdModel::kAuto, the default) against the calibration's
// constant thresholds for the same rate, on the same held-out samples.
TEST(CalibrationPanda, SpeedThresholdsAgainstConstantOnes) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig cfg = panda_config();
  const Model& model = cfg.robot.model;
  const std::vector<Sample> samples = panda_log(model);
  std::size_t first = 0;
  const std::vector<Sample> fit = fit_part(samples, first);
  const Calibration cal = calibrate(model, cfg.options, fit);
  const HoldoutReport rep = validate_holdout(model, cfg.options, cal, samples, first);
  std::printf("held out %d samples: false alarms %d (a + b|dq|), %d (constant)\n", rep.samples,
              rep.false_alarms, rep.constant_threshold_false_alarms);
  for (int i = 0; i < 7; ++i) {
    const JointFitReport& j = cal.joints[static_cast<std::size_t>(i)];
    std::printf(
        "joint %d: noise %.3f + %.3f|dq|; threshold %.3f + %.3f|dq| (mean %.3f) vs %.3f "
        "constant; %s\n",
        i + 1, j.noise_at_rest, j.noise_per_speed, j.threshold_at_rest, j.threshold_per_speed,
        j.mean_threshold_speed, j.threshold_constant, j.speed_dependent ? "speed" : "constant");
  }
  for (std::size_t l = 1; l <= 7; ++l)
    std::printf(
        "link %zu: smallest detectable force at 0.3 m %.3f N (chosen) vs %.3f N "
        "(constant calibrated) vs %.3f N (best constant, uncalibrated)\n",
        l, rep.min_force_calibrated[l], rep.min_force_calibrated_constant[l],
        rep.min_force_constant[l]);
  EXPECT_LE(rep.false_alarms, kMaxFalseAlarmShare * rep.samples);
}

// The residual filter (observer.residual_cutoff) on joints 1-4: their calibrated thresholds fall
// to at most 60 % of the unfiltered ones, the held-out motion stays quiet, the wrist's
// (unfiltered) thresholds do not move, and the model check had named those four joints.
TEST(CalibrationPanda, TheResidualFilterLowersTheProximalThresholds) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig plain = panda_config();
  const EstimatorConfig filtered = panda_config(kFilteredObserver);
  const Model& model = plain.robot.model;
  const std::vector<Sample> samples = panda_log(model);
  const auto first = static_cast<std::size_t>(kFitFraction * static_cast<double>(samples.size()));
  const std::vector<Sample> fit(samples.begin(), samples.begin() + static_cast<long>(first));
  const Calibration before = calibrate(model, plain.options, fit);
  const Calibration after = calibrate(model, filtered.options, fit);
  const HoldoutReport rep = validate_holdout(model, filtered.options, after, samples, first);
  EXPECT_LE(rep.false_alarms, kMaxFalseAlarmShare * rep.samples);
  for (int i = 0; i < 7; ++i) {
    const auto j = static_cast<std::size_t>(i);
    std::printf("joint %d: threshold %.3f + %.3f|dq| -> %.3f + %.3f|dq| N m, noise %.3f -> %.3f\n",
                i + 1, before.tau_threshold[i], before.tau_per_speed[i], after.tau_threshold[i],
                after.tau_per_speed[i], before.joints[j].noise_std, after.joints[j].noise_std);
    const double mean_before = before.joints[j].speed_dependent
                                   ? before.joints[j].mean_threshold_speed
                                   : before.tau_threshold[i];
    const double mean_after = after.joints[j].speed_dependent ? after.joints[j].mean_threshold_speed
                                                              : after.tau_threshold[i];
    if (i < 4) {
      EXPECT_LT(mean_after, 0.6 * mean_before) << "joint " << i + 1;
      EXPECT_LT(after.joints[j].noise_std, 0.7 * before.joints[j].noise_std) << "joint " << i + 1;
    } else {
      EXPECT_EQ(after.tau_threshold[i], before.tau_threshold[i]) << "joint " << i + 1;
    }
  }
  EXPECT_EQ(after.residual_cutoff, filtered.options.residual_cutoff);
  // The model check names what the filter removes, on joints 1-4 only, and not once filtered.
  const auto high_frequency_joints = [](const Calibration& c) {
    std::vector<int> joints;
    for (const ModelPattern& p : c.model_check.patterns)
      if (p.kind == "high_frequency") joints.push_back(p.joint);
    return joints;
  };
  EXPECT_EQ(high_frequency_joints(before), (std::vector<int>{1, 2, 3, 4}));
  EXPECT_TRUE(high_frequency_joints(after).empty());
  // What it is: the measured velocity's noise through the observer's momentum, K B(q) δq̇, whose
  // slope is 1 for a velocity error the torque does not see (an offline analysis with numpy gave
  // 0.96-0.97 and R² 0.95-0.99 on joints 1-4). Filtered, less of it is left, and on no wrist joint.
  const auto velocity_noise = [](const Calibration& c) {
    std::vector<int> joints;
    for (const ModelPattern& p : c.model_check.patterns) {
      if (p.kind != "velocity_noise") continue;
      joints.push_back(p.joint);
      const double slope = std::stod(p.message.substr(p.message.find("with slope ") + 11));
      EXPECT_NEAR(slope, 0.96, 0.04) << p.message;
    }
    return joints;
  };
  EXPECT_EQ(velocity_noise(before), (std::vector<int>{1, 2, 3, 4}));
  for (const int joint : velocity_noise(after)) EXPECT_LE(joint, 4);
  const auto share = [](const Calibration& c, int joint) {
    for (const ModelPattern& p : c.model_check.patterns)
      if (p.kind == "velocity_noise" && p.joint == joint) return p.share;
    return 0.0;
  };
  for (int joint = 1; joint <= 4; ++joint)
    EXPECT_LT(share(after, joint), 0.7 * share(before, joint)) << "joint " << joint;
}

// Friction that lags the reversals (the Dahl sign, --sign dahl), at acceptance 2's K = 50 with
// constant thresholds: on the wrist the measured torque takes a few mrad after each reversal to
// change sign (docs/calibration.md, real Panda), which a velocity sign cannot follow. Held out:
// still quiet; joints 5 and 7 keep much lower thresholds than with tanh, and links 5 and 7 get
// below the oracle of constant thresholds without calibration (links 4 and 6 do not).
TEST(CalibrationPanda, DahlFrictionLowersTheWristThresholds) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig cfg = panda_config();
  const Model& model = cfg.robot.model;
  const std::vector<Sample> samples = panda_log(model);
  std::size_t first = 0;
  const std::vector<Sample> fit = fit_part(samples, first);
  CalibrationOptions velocity_sign;
  velocity_sign.thresholds = ThresholdModel::kConstant;
  CalibrationOptions dahl = velocity_sign;
  dahl.sign = SmoothSign::kDahl;
  const Calibration tanh = calibrate(model, cfg.options, fit, velocity_sign);
  const Calibration cal = calibrate(model, cfg.options, fit, dahl);
  const HoldoutReport rep_tanh = validate_holdout(model, cfg.options, tanh, samples, first);
  const HoldoutReport rep = validate_holdout(model, cfg.options, cal, samples, first);
  EXPECT_LE(rep.false_alarms, kMaxFalseAlarmShare * rep.samples);
  for (int i = 0; i < 7; ++i) {
    std::printf(
        "joint %d: delta %.4f rad; threshold %.3f (tanh) -> %.3f N m; held-out max %.3f "
        "-> %.3f N m\n",
        i + 1, cal.friction.presliding[i], tanh.tau_threshold[i], cal.tau_threshold[i],
        rep_tanh.calibrated_max_residual[i], rep.calibrated_max_residual[i]);
  }
  for (std::size_t l = 4; l <= 7; ++l) {
    std::printf(
        "link %zu: smallest detectable force at 0.3 m %.3f (tanh) -> %.3f N; best "
        "constant without calibration %.3f N\n",
        l, rep_tanh.min_force_calibrated[l], rep.min_force_calibrated[l],
        rep.min_force_constant[l]);
  }
  for (const int i : {4, 6}) {  // joints 5 and 7
    EXPECT_LT(cal.tau_threshold[i], 0.7 * tanh.tau_threshold[i]) << "joint " << i + 1;
    EXPECT_LT(rep.calibrated_max_residual[i], 0.8 * rep_tanh.calibrated_max_residual[i])
        << "joint " << i + 1;
  }
  for (const std::size_t l : {5u, 7u}) {
    EXPECT_LT(rep.min_force_calibrated[l], rep.min_force_constant[l]) << "link " << l;
    EXPECT_LT(rep.min_force_calibrated[l], rep_tanh.min_force_calibrated[l]) << "link " << l;
  }
  // The tanh calibration's model check names the lag on the joints where the Dahl sign then
  // lowers the held-out residual (5 and 7) and on no joint whose residual is noise (1-4); the
  // Dahl calibration has nothing left to name.
  std::vector<int> presliding;
  for (const ModelPattern& p : tanh.model_check.patterns) {
    if (p.kind != "presliding") continue;
    std::printf("%s\n", p.message.c_str());
    presliding.push_back(p.joint);
    EXPECT_NE(p.message.find("--sign dahl"), std::string::npos);
  }
  EXPECT_NE(std::find(presliding.begin(), presliding.end(), 5), presliding.end());
  EXPECT_NE(std::find(presliding.begin(), presliding.end(), 7), presliding.end());
  for (const int j : presliding) EXPECT_GE(j, 5);
  for (const ModelPattern& p : cal.model_check.patterns) EXPECT_NE(p.kind, "presliding");
}

// The inertia correction (--inertia) with the velocity filter and the residual filter on joints
// 1-4: the fit finds the robot's inertia along joint 4 smaller than the identified model's (the
// model check's inertia pattern); its gravity columns keep it off joints 5 and 7, whose q̈
// follows a payload's gravity in this motion. Held out: still quiet, joint 4's residual lower
// at its peak and in its spread, and its threshold with it; the force detectable at 0.3 m on
// links 4-7 does not rise. With the residual filter alone (the momentum's q̇ the measured one,
// its noise a nuisance column of the fit) the same δI on joint 4 is found.
TEST(CalibrationPanda, TheInertiaCorrectionLowersJointFour) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig cfg = panda_config(
      "{gain: 50, residual_cutoff: [20, 20, 20, 20, 0, 0, 0], "
      "velocity_cutoff: [20, 20, 20, 20, 0, 0, 0]}");
  const Model& model = cfg.robot.model;
  const std::vector<Sample> samples = panda_log(model);
  const auto first = static_cast<std::size_t>(kFitFraction * static_cast<double>(samples.size()));
  const std::vector<Sample> fit(samples.begin(), samples.begin() + static_cast<long>(first));
  CalibrationOptions with_inertia;
  with_inertia.inertia_correction = true;
  const Calibration plain = calibrate(model, cfg.options, fit);
  const Calibration cal = calibrate(model, cfg.options, fit, with_inertia);
  const HoldoutReport rep_plain = validate_holdout(model, cfg.options, plain, samples, first);
  const HoldoutReport rep = validate_holdout(model, cfg.options, cal, samples, first);
  for (int i = 0; i < 7; ++i) {
    std::printf(
        "joint %d: dI %.4f kg m^2; threshold %.3f -> %.3f N m; held-out max %.3f -> %.3f N m\n",
        i + 1, cal.inertia_correction[i], plain.tau_threshold[i], cal.tau_threshold[i],
        rep_plain.calibrated_max_residual[i], rep.calibrated_max_residual[i]);
  }
  for (std::size_t l = 4; l <= 7; ++l) {
    std::printf("link %zu: smallest detectable force at 0.3 m %.3f -> %.3f N\n", l,
                rep_plain.min_force_calibrated[l], rep.min_force_calibrated[l]);
    EXPECT_LE(rep.min_force_calibrated[l], rep_plain.min_force_calibrated[l]) << "link " << l;
  }
  EXPECT_LE(rep.false_alarms, kMaxFalseAlarmShare * rep.samples);
  EXPECT_LT(cal.inertia_correction[3], -0.05);
  EXPECT_GT(cal.inertia_correction[3], -0.2);
  for (const int i : {1, 2, 4, 6}) EXPECT_EQ(cal.inertia_correction[i], 0.0) << "joint " << i + 1;
  EXPECT_LT(cal.tau_threshold[3], 0.9 * plain.tau_threshold[3]);
  EXPECT_LT(rep.calibrated_max_residual[3], 0.9 * rep_plain.calibrated_max_residual[3]);
  EXPECT_LT(cal.joints[3].noise_std, 0.8 * plain.joints[3].noise_std);

  const EstimatorConfig residual_only = panda_config(kFilteredObserver);
  const Calibration unfiltered_dq = calibrate(model, residual_only.options, fit, with_inertia);
  for (int i = 0; i < 7; ++i)
    std::printf("residual filter alone: joint %d: dI %.4f kg m^2\n", i + 1,
                unfiltered_dq.inertia_correction[i]);
  EXPECT_NEAR(unfiltered_dq.inertia_correction[3], cal.inertia_correction[3],
              0.2 * std::abs(cal.inertia_correction[3]));
}

// A 15 N push superposed on the real torques (τ − J_lᵀ F) from 80 % of the log on: a point
// 0.1 m from link l's origin, perpendicular to its joint axis, the force tangential (fixed in
// the link frame). Detected within 50 ms, on link l, for the wrist links whose thresholds the
// calibration lowers most; links 3 and 4 are reported (their 1/h thresholds exceed what such a
// push makes on joints 1-4).
TEST(CalibrationPanda, PushSuperposedOnTheRealTorquesIsDetectedOnTheWrist) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig cfg = panda_config();
  const Model& model = cfg.robot.model;
  const auto [free, first, cal] = calibrated_on_fit_part(cfg);
  const std::size_t start = free.size() * 8 / 10;
  Data data(model);
  Matrix6X J = Matrix6X::Zero(6, model.nq());
  for (int link = 3; link <= 7; ++link) {
    const Vector3& axis = model.joints[static_cast<std::size_t>(link)].axis;
    Vector3 lever_L = axis.cross(Vector3::UnitX());
    if (lever_L.norm() < 0.1) lever_L = axis.cross(Vector3::UnitY());
    lever_L = 0.1 * lever_L.normalized();
    const Vector3 force_L = 15.0 * axis.cross(lever_L).normalized();
    std::vector<Sample> pushed = free;
    for (std::size_t k = start; k < pushed.size(); ++k) {
      forward_kinematics(model, data, pushed[k].q);
      const Pose& X_WL = data.X_WB[static_cast<std::size_t>(link)];
      point_jacobian(model, data, link, X_WL.act(lever_L), J);
      pushed[k].tau -= J.topRows<3>().transpose() * (X_WL.rotation * force_L);
    }
    ContactEstimator est(model, cfg.robot.geometry, apply_calibration(cfg.options, cal));
    ASSERT_TRUE(est.reset(pushed.front()).ok());
    double delay = -1.0;
    int isolated = -1, isolated_at_window = -1;
    for (std::size_t k = 1; k < pushed.size(); ++k) {
      ASSERT_TRUE(est.update(pushed[k]).ok());
      if (k >= start && delay < 0 && est.result().contact) {
        delay = pushed[k].t - pushed[start].t;
        isolated = est.result().link;
      }
      // The link when the 50 ms window closes: with thresholds that follow |q̇| a proximal joint
      // can cross first (joint 4 for a push on link 5), the distal one a few ms later.
      if (k >= start && isolated_at_window < 0 && pushed[k].t - pushed[start].t >= 0.05)
        isolated_at_window = est.result().link;
    }
    RecordProperty("push_link" + std::to_string(link),
                   "delay " + std::to_string(delay) + " s, isolated " + std::to_string(isolated) +
                       ", at 50 ms " + std::to_string(isolated_at_window));
    std::printf("push on link %d: delay %.4f s, isolated link %d (at 50 ms: %d)\n", link, delay,
                isolated, isolated_at_window);
    if (link >= 5) {
      EXPECT_GE(delay, 0.0) << "link " << link;
      EXPECT_LE(delay, 0.05) << "link " << link;
      EXPECT_EQ(isolated_at_window, link);
    }
  }
}

// Acceptance 2's pushes at surface points: on each of links 3-7, a pusher comes along each axis
// of the link frame (±x, ±y, ±z) aimed at the centre of the link's collision shapes; where it
// first meets the arm on that link (no other link in the way), a 15 N force along its direction
// acts from 80 % of the log on (fixed in the link frame), superposed on the real torques as
// τ − J_vᵀ F. K = 50 with the residual filter on joints 1-4. Every push whose torque is clearly
// over a threshold is detected within 50 ms, and every push whose link is observable is on that
// link at 50 ms. Without the filter 13 of the 19 are detected in time (17 with it).
struct SurfacePush {
  int link = 0;
  Vector3 point_L, force_L;
};

std::vector<SurfacePush> surface_pushes(const Model& model, const GeometryModel& geometry,
                                        const VectorX& q) {
  Data data(model);
  forward_kinematics(model, data, q);
  std::vector<SurfacePush> pushes;
  for (int link = 3; link <= 7; ++link) {
    const auto l = static_cast<std::size_t>(link);
    Vector3 lo = Vector3::Constant(1e9), hi = Vector3::Constant(-1e9);
    for (int s : geometry.body_shapes[l]) {
      const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
      if (shape.type != ShapeType::kMesh) continue;
      for (Eigen::Index v = 0; v < shape.mesh->vertices.cols(); ++v) {
        const Vector3 p = shape.placement.act(shape.mesh->vertices.col(v));
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
    if (!(lo.array() <= hi.array()).all()) continue;
    const Pose& X_WL = data.X_WB[l];
    const Vector3 centre_W = X_WL.act(0.5 * (lo + hi));
    for (int axis = 0; axis < 6; ++axis) {
      const Vector3 d_L = (axis % 2 == 0 ? 1.0 : -1.0) * Vector3::Unit(axis / 2);
      const Vector3 d_W = X_WL.rotation * d_L;
      const Vector3 start_W = centre_W - 2.0 * d_W;
      const SurfacePointResult on_link =
          intersect_line_with_body(geometry, link, X_WL, start_W, d_W, OnMiss::kNothing);
      if (!on_link.hit) continue;
      bool blocked = false;
      for (int b = 0; b < model.num_bodies() && !blocked; ++b) {
        if (b == link) continue;
        const SurfacePointResult other = intersect_line_with_body(
            geometry, b, data.X_WB[static_cast<std::size_t>(b)], start_W, d_W, OnMiss::kNothing);
        blocked = other.hit && other.entry.lambda < on_link.entry.lambda;
      }
      if (blocked) continue;
      pushes.push_back({link, X_WL.inverse().act(on_link.entry.point_W), 15.0 * d_L});
    }
  }
  return pushes;
}

TEST(CalibrationPanda, PushesAtSurfacePointsAreDetectedWithin50ms) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig cfg = panda_config(kFilteredObserver);
  const Model& model = cfg.robot.model;
  const auto [free, first, cal] = calibrated_on_fit_part(cfg);
  const std::size_t start = free.size() * 8 / 10;
  const std::vector<SurfacePush> pushes = surface_pushes(model, cfg.robot.geometry, free[start].q);
  Data data(model);
  Matrix6X J = Matrix6X::Zero(6, model.nq());
  const EstimatorOptions options = apply_calibration(cfg.options, cal);
  int detected = 0, right = 0, detectable_count = 0, observable_count = 0;
  double worst_force_error = 0.0;
  for (const SurfacePush& push : pushes) {
    std::vector<Sample> pushed = free;
    const auto l = static_cast<std::size_t>(push.link);
    for (std::size_t k = start; k < pushed.size(); ++k) {
      forward_kinematics(model, data, pushed[k].q);
      const Pose& X_WL = data.X_WB[l];
      point_jacobian(model, data, push.link, X_WL.act(push.point_L), J);
      pushed[k].tau -= J.topRows<3>().transpose() * (X_WL.rotation * push.force_L);
    }
    ContactEstimator est(model, cfg.robot.geometry, options);
    ASSERT_TRUE(est.reset(pushed.front()).ok());
    double delay = -1.0, over = 0.0, own = 0.0;
    int at_window = -1;
    bool early = false;
    // How hard: ‖F̂ − F‖ and ‖F‖ over the samples from 50 ms after the push on, where the
    // contact is declared on the push's link with a force estimate.
    double error_sq = 0.0, force_sq = 0.0;
    int estimated = 0, after_window = 0;
    for (std::size_t k = 1; k < pushed.size(); ++k) {
      ASSERT_TRUE(est.update(pushed[k]).ok());
      if (k >= start && pushed[k].t - pushed[start].t >= 0.05) {
        ++after_window;
        const ContactEstimate& e = est.result();
        if (e.contact && e.link == push.link && e.has(EstimateFlag::kForce) &&
            !e.has(EstimateFlag::kPartial)) {
          forward_kinematics(model, data, pushed[k].q);
          const Vector3 F = data.X_WB[l].rotation * push.force_L;
          error_sq += (e.force_W - F).squaredNorm();
          force_sq += F.squaredNorm();
          ++estimated;
        }
      }
      if (k >= first && k < start && est.result().contact) early = true;
      if (k >= start && delay < 0 && est.result().contact) delay = pushed[k].t - pushed[start].t;
      if (k >= start && at_window < 0 && pushed[k].t - pushed[start].t >= 0.05) {
        at_window = est.result().link;
        // What the residual can see of this push: its torque over each joint's threshold.
        forward_kinematics(model, data, pushed[k].q);
        point_jacobian(model, data, push.link, data.X_WB[l].act(push.point_L), J);
        const VectorX tau_push =
            J.topRows<3>().transpose() * (data.X_WB[l].rotation * push.force_L);
        const VectorX ratio = tau_push.cwiseAbs().cwiseQuotient(est.detector().thresholds());
        over = ratio.maxCoeff();
        own = ratio[push.link - 1];
      }
    }
    EXPECT_FALSE(early) << "a false alarm on the held-out free motion before the push";
    // Detectable: the push's torque is clearly over some joint's threshold (after 50 ms the
    // residual, K = 50 and the filter, has reached ~85 % of it). The link is observable when
    // the paper's rule can name it (its own joint clearly over) or, without a sensor, when the
    // geometry test has a line to test (links 6-7: a pure force's line takes 5 joints, a test
    // of it one more; Table I case E).
    const bool detectable = over >= kClearMargin;
    const bool observable = detectable && (own >= kClearMargin || push.link >= 6);
    const bool in_time = delay >= 0 && delay <= 0.05 + 1e-9;
    const double force_error = estimated > 0 ? std::sqrt(error_sq / force_sq) : -1.0;
    detected += in_time ? 1 : 0;
    right += in_time && at_window == push.link ? 1 : 0;
    detectable_count += detectable ? 1 : 0;
    observable_count += observable ? 1 : 0;
    if (detectable) {
      EXPECT_TRUE(in_time) << "link " << push.link << ", delay " << delay;
    }
    if (observable) {
      EXPECT_EQ(at_window, push.link);
      // The force (case E: no sensor, a pure force at an unknown point) against the one
      // superposed, on the real arm's residual: 9.8-13.1 % RMS measured.
      EXPECT_GT(estimated, after_window / 4) << "link " << push.link;
      EXPECT_LT(force_error, kMaxPushForceError) << "link " << push.link;
      worst_force_error = std::max(worst_force_error, force_error);
    }
    std::printf(
        "link %d, point_L (%+.3f %+.3f %+.3f), force_L (%+.0f %+.0f %+.0f) N: torque / threshold "
        "%.2f (own joint %.2f); delay %.3f s, link at 50 ms %d; force error %.1f %% on %d of %d "
        "samples\n",
        push.link, push.point_L.x(), push.point_L.y(), push.point_L.z(), push.force_L.x(),
        push.force_L.y(), push.force_L.z(), over, own, delay, at_window, 100.0 * force_error,
        estimated, after_window);
  }
  std::printf(
      "%d pushes at surface points: %d detected within 50 ms (%d clearly over a threshold), %d "
      "on the right link at 50 ms (%d observable)\n",
      static_cast<int>(pushes.size()), detected, detectable_count, right, observable_count);
  std::printf("worst force error of an observable push: %.1f %%\n", 100.0 * worst_force_error);
  RecordProperty("surface_pushes", std::to_string(pushes.size()) + " pushes, " +
                                       std::to_string(detected) + " detected within 50 ms, " +
                                       std::to_string(right) + " on the right link");
  EXPECT_GE(pushes.size(), 15u);
}

}  // namespace
}  // namespace extwrench
