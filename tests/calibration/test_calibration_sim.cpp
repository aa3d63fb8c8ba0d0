// Calibration against simulated truth (issue 10, acceptance 1): the paper arm with friction,
// torque offsets, a biased noisy F/T sensor and torque noise that its model does not contain.
#include <gtest/gtest.h>

#include <cstdlib>

#include "calibration_sim.hpp"
#include "extwrench/calibration/calibration.hpp"
#include "extwrench/estimation/contact_estimator.hpp"

namespace extwrench {
namespace {

constexpr double kTauNoise = 0.02;             // [N m] per joint torque sample
constexpr double kFrictionTolerance = 0.05;    // relative, acceptance 1
constexpr double kOffsetTolerance = 0.02;      // [N m]
constexpr double kBiasForceTolerance = 0.1;    // [N]
constexpr double kBiasMomentTolerance = 0.01;  // [N m]
constexpr double kDetectionDelay = 0.05;       // [s]

Vector6 true_bias() {
  Vector6 b;
  b << 1.5, -2.0, 3.0, 0.2, -0.15, 0.1;
  return b;
}

EstimatorOptions ft_options() {
  EstimatorOptions o;
  o.sensor.type = SensorType::kForceTorque;
  o.observer_gain = VectorX::Constant(1, 100.0);
  return o;
}

// One calibration shared by the tests of this file (it takes a few seconds to simulate).
const Calibration& shared_calibration() {
  static const Calibration cal = [] {
    const Model model = paper_arm();
    const auto log =
        test::simulate_free_motion(model, test::free_motion(0.0, 1.0), test::paper_arm_friction(),
                                   40.0, true_bias(), kTauNoise, 11);
    return calibrate(model, ft_options(), log);
  }();
  return cal;
}

TEST(CalibrationSim, RecoversFrictionOffsetsAndSensorBias) {
  const Calibration& cal = shared_calibration();
  const test::TrueFriction truth = test::paper_arm_friction();
  for (int i = 0; i < 7; ++i) {
    SCOPED_TRACE("joint " + std::to_string(i + 1));
    EXPECT_NEAR(cal.friction.viscous[i], truth.viscous[i], kFrictionTolerance * truth.viscous[i]);
    EXPECT_NEAR(cal.friction.coulomb[i], truth.coulomb[i], kFrictionTolerance * truth.coulomb[i]);
    EXPECT_NEAR(cal.friction.offset[i], truth.offset[i], kOffsetTolerance);
    EXPECT_GT(cal.joints[static_cast<std::size_t>(i)].variance_explained, 0.9);
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(cal.sensor_bias_S[a], true_bias()[a], kBiasForceTolerance);
    EXPECT_NEAR(cal.sensor_bias_S[3 + a], true_bias()[3 + a], kBiasMomentTolerance);
  }
  EXPECT_TRUE(cal.suspect_windows.empty());
}

double free_seconds() {
  const char* s = std::getenv("EXTWRENCH_CALIBRATION_FREE_SECONDS");  // 600 for acceptance 1
  return s != nullptr ? std::atof(s) : 60.0;
}

// New free motion: other phases, other noise, the same speeds as the calibration motion (the
// calibration covers the motion it saw: docs/calibration.md).
TEST(CalibrationSim, NoFalseAlarmOnNewFreeMotion) {
  const Model model = paper_arm();
  const double seconds = free_seconds();
  const auto log =
      test::simulate_free_motion(model, test::free_motion(0.9, 1.0), test::paper_arm_friction(),
                                 seconds, true_bias(), kTauNoise, 23);
  ContactEstimator est(model, GeometryModel{},
                       apply_calibration(ft_options(), shared_calibration()));
  ASSERT_TRUE(est.reset(log.front()).ok());
  int alarms = 0;
  VectorX peak = VectorX::Zero(7);
  double peak_force = 0.0;
  for (std::size_t k = 1; k < log.size(); ++k) {
    ASSERT_TRUE(est.update(log[k]).ok());
    if (est.result().contact) ++alarms;
    if (log[k].t < 0.1) continue;
    peak = peak.cwiseMax(est.result().residual.cwiseAbs());
    peak_force = std::max(peak_force, est.result().force_W.norm());
  }
  EXPECT_EQ(alarms, 0) << "over " << seconds << " s of new free motion; largest residuals "
                       << peak.transpose() << " for thresholds "
                       << shared_calibration().tau_threshold.transpose() << "; largest force "
                       << peak_force << " N for " << shared_calibration().force_threshold << " N";
}

// A 10 N push, tangential at 0.1 m from each link's joint axis (z of its DH frame), half-way.
TEST(CalibrationSim, DetectsATenNewtonPushOnEveryLinkWithinFiftyMilliseconds) {
  const Model model = paper_arm();
  const EstimatorOptions options = apply_calibration(ft_options(), shared_calibration());
  for (int link = 2; link <= 7; ++link) {
    SCOPED_TRACE("link " + std::to_string(link));
    sim::ForceProfile push;
    push.frame = "link" + std::to_string(link);
    push.axes = sim::ForceProfile::Axes::kFrame;
    push.point_F = Vector3(0.1, 0.0, 0.0);
    push.force = Vector3(0.0, 10.0, 0.0);
    push.start = 2.0;
    push.end = 3.0;
    const auto log = test::simulate_free_motion(
        model, test::free_motion(0.4, 1.0), test::paper_arm_friction(), 3.0, true_bias(), kTauNoise,
        31 + static_cast<unsigned>(link), {push});
    ContactEstimator est(model, GeometryModel{}, options);
    ASSERT_TRUE(est.reset(log.front()).ok());
    double detected = -1.0;
    for (std::size_t k = 1; k < log.size(); ++k) {
      ASSERT_TRUE(est.update(log[k]).ok());
      if (log[k].t < push.start) {
        EXPECT_FALSE(est.result().contact) << "false alarm at t = " << log[k].t;
      } else if (est.result().contact && detected < 0) {
        detected = log[k].t - push.start;
      }
    }
    EXPECT_GE(detected, 0.0);
    EXPECT_LE(detected, kDetectionDelay);
  }
}

}  // namespace
}  // namespace extwrench
