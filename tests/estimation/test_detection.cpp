// ContactDetector's release from the base sensor (docs/estimator.md#release-from-the-sensor):
// a release the residual confirms stays a release, even after a large push; a release the
// residual contradicts (the force is still there) is undone and not repeated.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/estimation/detection.hpp"
#include "support/test_robots.hpp"

namespace extwrench {
namespace {

constexpr int kJoints = 3;
constexpr double kDt = 0.001;      // [s]
constexpr double kGain = 100.0;    // observer gain K [1/s]: the residual decays as e^{-K t}
constexpr double kSettle = 0.05;   // 5 time constants, as the estimator passes
constexpr double kForceOff = 0.5;  // [s] when the sensor says the force is gone

/// What the detector sees over 1 s: a push from 0.1 s of residual `level` × τ_min on joint 2
/// and base force `level` × F_min. The sensor's instantaneous force drops to 0 at kForceOff;
/// the residual and the lagged base force decay from then on only if `force_ends`.
struct ReleaseRun {
  int declared_after_off = 0;  ///< samples with a declared contact after kForceOff + 20 ms
  int onsets = 0;              ///< rising edges of the declared contact
  double released_at = NAN;    ///< first release after kForceOff [s]
};

/// `measured`: what the force with q̈ measured reads after kForceOff (NaN: not given).
ReleaseRun run_detector(double level, bool force_ends, double measured = NAN) {
  DetectionOptions options;  // τ_min 1, F_min 5, ratio 0.5, min_duration 5 ms, sensor release 1 ms
  ContactDetector detector(options, kJoints, kSettle);
  ReleaseRun out;
  bool was = false;
  for (int k = 0; k <= 1000; ++k) {
    const double t = k * kDt;
    double size = t < 0.1 ? 0.0 : level;
    if (force_ends && t > kForceOff) size = level * std::exp(-kGain * (t - kForceOff));
    VectorX tau_ext = VectorX::Zero(kJoints);
    tau_ext[1] = size * options.tau_min[0];
    const double base_force = size * options.f_min;
    const double release_force = t < 0.1 ? NAN : (t > kForceOff ? 0.0 : base_force);
    const double measured_force = t > kForceOff ? measured : release_force;
    const DetectionResult& det =
        detector.update(t, tau_ext, base_force, release_force, measured_force);
    if (det.contact && !was) ++out.onsets;
    if (!det.contact && was && t > kForceOff && std::isnan(out.released_at)) out.released_at = t;
    if (det.contact && t > kForceOff + 0.02) ++out.declared_after_off;
    was = det.contact;
  }
  return out;
}

TEST(Detection, ASensorReleaseTheResidualConfirmsStaysReleased) {
  for (const double level : {3.0, 20.0, 200.0}) {  // 200: still over its threshold at 5 τ
    const ReleaseRun r = run_detector(level, true);
    EXPECT_EQ(r.onsets, 1) << level;
    EXPECT_NEAR(r.released_at, kForceOff + 0.005, 1.5e-3) << level;  // min_duration
    EXPECT_EQ(r.declared_after_off, 0) << level;
  }
}

// The force with q̈ measured assumes no contact point: when it agrees that the force is gone the
// release waits sensor_release_duration (1 ms: the second sample below the level), not
// min_duration; when it still reads the push (the point-dependent force dipped alone) the release
// keeps min_duration.
TEST(Detection, TheMeasuredForceShortensTheSensorRelease) {
  for (const double level : {3.0, 20.0}) {
    const ReleaseRun agreed = run_detector(level, true, 0.0);
    EXPECT_EQ(agreed.onsets, 1) << level;
    EXPECT_NEAR(agreed.released_at, kForceOff + 0.001 + kDt, 1e-9) << level;
    EXPECT_EQ(agreed.declared_after_off, 0) << level;
    const ReleaseRun disagreed = run_detector(level, true, 10.0);  // over ratio × F_min = 2.5 N
    EXPECT_NEAR(disagreed.released_at, kForceOff + 0.005 + kDt, 1e-9) << level;
  }
}

TEST(Detection, ASensorReleaseTheResidualContradictsIsUndoneOnce) {
  // The sensor's force fell to 0 but the residual stays: the force is on another link than
  // the one the release assumed. The contact is declared again after the settle time and then
  // held (no release/onset cycles) while the residual lasts.
  const ReleaseRun r = run_detector(10.0, false);
  EXPECT_EQ(r.onsets, 2);
  EXPECT_NEAR(r.released_at, kForceOff + 0.005, 1.5e-3);
  const int samples_after = 1000 - static_cast<int>((kForceOff + 0.02) / kDt);
  // Re-declared at release + settle + min_duration, then held to the end.
  EXPECT_GE(r.declared_after_off, samples_after - static_cast<int>((kSettle + 0.012) / kDt));
}

// Thresholds that follow the motion (docs/calibration.md#thresholds-that-follow-the-motion):
// τ_thr,i = τ_min,i + b_i |q̇_i|; the same residual is over at rest and under when moving fast.
TEST(Detection, SpeedThresholdsRiseWithTheJointSpeed) {
  DetectionOptions options;
  options.tau_min = VectorX::Constant(kJoints, 1.0);
  options.tau_per_speed = VectorX::Zero(kJoints);
  options.tau_per_speed[1] = 2.0;  // joint 2: 1 + 2 |q̇| N m
  options.min_duration = 0.0;
  ContactDetector detector(options, kJoints);
  EXPECT_TRUE(detector.speed_dependent());
  VectorX tau_ext = VectorX::Zero(kJoints);
  tau_ext[1] = 1.5;
  VectorX dq = VectorX::Zero(kJoints);
  dq[1] = -0.5;  // threshold 2 N m on joint 2
  detector.set_motion(dq);
  EXPECT_DOUBLE_EQ(detector.thresholds()[1], 2.0);
  EXPECT_DOUBLE_EQ(detector.tau_min()[0], 1.0);
  EXPECT_FALSE(detector.update(0.0, tau_ext, NAN).raw);
  dq[1] = 0.1;  // threshold 1.2 N m
  detector.set_motion(dq);
  const DetectionResult& det = detector.update(kDt, tau_ext, NAN);
  EXPECT_TRUE(det.contact);
  EXPECT_EQ(det.link, 2);
  // Hysteresis at the threshold in force: released below 0.5 × (1 + 2 · 0.8) = 1.3 N m.
  dq[1] = 0.8;
  detector.set_motion(dq);
  EXPECT_TRUE(detector.update(2 * kDt, tau_ext, NAN).contact);
  tau_ext[1] = 1.2;
  EXPECT_FALSE(detector.update(3 * kDt, tau_ext, NAN).contact);
  // Constant thresholds: set_motion changes nothing.
  ContactDetector constant(DetectionOptions{}, kJoints);
  EXPECT_FALSE(constant.speed_dependent());
  constant.set_motion(VectorX::Constant(kJoints, 10.0));
  EXPECT_DOUBLE_EQ(constant.tau_min()[2], 1.0);
}

// The factors of the terms that follow the motion, b (tau_per_speed) and c (inertial_margin):
// none, one or n of them, each finite and >= 0.
TEST(Detection, MotionThresholdFactorsAreValidated) {
  for (VectorX DetectionOptions::*factor :
       {&DetectionOptions::tau_per_speed, &DetectionOptions::inertial_margin}) {
    DetectionOptions options;
    options.*factor = VectorX::Constant(2, 0.1);
    EXPECT_THROW(validate(options, kJoints), Error);
    options.*factor = VectorX::Constant(1, -0.1);
    EXPECT_THROW(validate(options, kJoints), Error);
    options.*factor = VectorX::Constant(1, NAN);
    EXPECT_THROW(validate(options, kJoints), Error);
    options.*factor = VectorX::Constant(1, 0.1);
    EXPECT_NO_THROW(validate(options, kJoints));
    options.*factor = VectorX::Constant(kJoints, 0.01);
    EXPECT_NO_THROW(validate(options, kJoints));
  }
}

// The inertial margin (docs/calibration.md#thresholds-that-follow-the-motion): τ_thr,i =
// τ_min,i + b_i |q̇_i| + c_i |τ_dyn,i|, the same residual over while the arm coasts and under
// while it is accelerated hard.
TEST(Detection, InertialMarginRisesWithTheDynamicTorque) {
  DetectionOptions options;
  options.tau_min = VectorX::Constant(kJoints, 1.0);
  options.tau_per_speed = VectorX::Constant(1, 2.0);
  options.inertial_margin = VectorX::Constant(kJoints, 0.05);
  options.min_duration = 0.0;
  ContactDetector detector(options, kJoints);
  EXPECT_TRUE(detector.inertia_dependent());
  VectorX tau_ext = VectorX::Zero(kJoints);
  tau_ext[2] = 2.0;
  VectorX dq = VectorX::Zero(kJoints);
  dq[2] = 0.25;  // 1 + 2 · 0.25 = 1.5 N m from the speed
  VectorX dynamic = VectorX::Zero(kJoints);
  dynamic[2] = -20.0;  // + 0.05 · 20 = 2.5 N m
  dynamic[0] = 4.0;
  detector.set_motion(dq, dynamic);
  EXPECT_DOUBLE_EQ(detector.thresholds()[2], 2.5);
  EXPECT_DOUBLE_EQ(detector.thresholds()[0], 1.2);
  EXPECT_DOUBLE_EQ(detector.thresholds()[1], 1.0);
  EXPECT_FALSE(detector.update(0.0, tau_ext, NAN).raw);
  dynamic[2] = 5.0;  // 1.75 N m: 2 N m is over
  detector.set_motion(dq, dynamic);
  EXPECT_DOUBLE_EQ(detector.thresholds()[2], 1.75);
  EXPECT_TRUE(detector.update(kDt, tau_ext, NAN).contact);
  // set_motion(q̇) alone: the speed part only.
  detector.set_motion(dq);
  EXPECT_DOUBLE_EQ(detector.thresholds()[2], 1.5);
  // Without a margin the dynamic torque changes nothing.
  options.inertial_margin.resize(0);
  ContactDetector speed_only(options, kJoints);
  EXPECT_FALSE(speed_only.inertia_dependent());
  speed_only.set_motion(dq, dynamic);
  EXPECT_DOUBLE_EQ(speed_only.thresholds()[2], 1.5);
}

// In the estimator τ_dyn is τ − τ_f − g(q) + τ̂_ext = B q̈ + C q̇ (the torque that accelerates
// the arm): its thresholds after every sample against g(q) from gravity_torques (the body-frame
// pass, not the estimator's world-frame momentum pass) and the residual it reports.
TEST(Detection, TheEstimatorsInertialMarginUsesTheDynamicTorque) {
  const Model model = test::paper_arm_model();
  const int n = model.nq();
  EstimatorOptions options;
  options.sensor.type = SensorType::kNone;
  options.friction = JointFriction::none(n);
  options.detection.tau_min = VectorX::Constant(1, 1.0);
  options.detection.inertial_margin = VectorX::LinSpaced(n, 0.01, 0.07);
  ContactEstimator estimator(model, GeometryModel{}, options);
  Data data(model);
  VectorX q(n), dq(n), tau(n);
  const auto state = [&](double t) {
    for (int i = 0; i < n; ++i) {
      q[i] = 0.3 * std::sin(2.0 * t + i);
      dq[i] = 0.6 * std::cos(2.0 * t + i);
    }
    // Gravity plus a torque that accelerates the arm (not its true dynamics: the relation under
    // test holds for any input).
    tau =
        gravity_torques(model, data, q) + 5.0 * VectorX::LinSpaced(n, 1.0, -1.0) * std::sin(9 * t);
  };
  state(0.0);
  ASSERT_TRUE(estimator.reset(0.0, q, dq, tau).ok());
  double largest = 0.0;
  for (int k = 1; k <= 300; ++k) {
    const double t = k * kDt;
    state(t);
    ASSERT_TRUE(estimator.update(t, q, dq, tau).ok());
    const VectorX dynamic = tau - gravity_torques(model, data, q) + estimator.result().residual;
    for (int i = 0; i < n; ++i) {
      const double expected = 1.0 + options.detection.inertial_margin[i] * std::abs(dynamic[i]);
      EXPECT_NEAR(estimator.detector().thresholds()[i], expected, 1e-12) << "joint " << i + 1;
      largest = std::max(largest, expected - 1.0);
    }
  }
  EXPECT_GT(largest, 0.1);  // the margin did move the thresholds
}

}  // namespace
}  // namespace extwrench
