// Calibration on a real robot (issue 10, acceptance 2): the Franka Panda's contact-free
// identification trajectory (../shared/realdata/franka_panda_free_motion), K = 50, fitted on the
// first 60 % and judged on the last 40 %. Skips when ../shared is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "extwrench/calibration/holdout.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
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

EstimatorConfig panda_config() {
  return load_estimator_config_string("robot: " + (panda_dir() / "panda.urdf").string() +
                                          "\nsensor: {type: none}\nobserver: {gain: 50}\n",
                                      panda_dir() / "config.yaml");
}

std::vector<Sample> panda_log(const Model& model) {
  std::vector<Sample> samples;
  LogReader reader(panda_dir() / "log.csv", model);
  Sample s;
  while (reader.next(s)) samples.push_back(s);
  return samples;
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
  const auto first = static_cast<std::size_t>(kFitFraction * static_cast<double>(samples.size()));
  const std::vector<Sample> fit(samples.begin(), samples.begin() + static_cast<long>(first));
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

// A 15 N push superposed on the real torques (τ − J_lᵀ F) from 80 % of the log on: a point
// 0.1 m from link l's origin, perpendicular to its joint axis, the force tangential (fixed in
// the link frame). Detected within 50 ms, on link l, for the wrist links whose thresholds the
// calibration lowers most; links 3 and 4 are reported (their 1/h thresholds exceed what such a
// push makes on joints 1-4).
TEST(CalibrationPanda, PushSuperposedOnTheRealTorquesIsDetectedOnTheWrist) {
  if (!fs::exists(panda_dir() / "log.csv")) GTEST_SKIP() << "no " << panda_dir();
  const EstimatorConfig cfg = panda_config();
  const Model& model = cfg.robot.model;
  const std::vector<Sample> free = panda_log(model);
  const auto first = static_cast<std::size_t>(kFitFraction * static_cast<double>(free.size()));
  const Calibration cal =
      calibrate(model, cfg.options,
                std::vector<Sample>(free.begin(), free.begin() + static_cast<long>(first)));
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

}  // namespace
}  // namespace extwrench
