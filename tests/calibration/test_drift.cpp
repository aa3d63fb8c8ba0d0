// Slow drift tracking (issue 10, EstimatorOptions::drift): joint torque offsets and a base F/T
// bias that creep during a long run, against simulated truth. With tracking the estimator stays
// quiet and its offsets and bias follow the true ones; without it, the same run false-alarms.
// During a push the tracked values are frozen, and the push is still detected.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "calibration_sim.hpp"
#include "extwrench/estimation/contact_estimator.hpp"

namespace extwrench {
namespace {

constexpr double kDuration = 120.0;        // [s]
constexpr double kOffsetRate = 0.004;      // [N m/s] per joint, alternating sign
constexpr double kBiasForceRate = 0.03;    // [N/s] per sensor force axis
constexpr double kBiasMomentRate = 0.002;  // [N m/s] per sensor moment axis
constexpr double kPushStart = 80.0, kPushEnd = 83.0;

test::TrueFriction offsets_only() {
  test::TrueFriction f = test::paper_arm_friction();
  f.viscous.setZero();
  f.coulomb.setZero();
  return f;
}

Vector6 initial_bias() {
  Vector6 b;
  b << 1.0, -0.5, 2.0, 0.1, -0.05, 0.02;
  return b;
}

double drift_sign(int i) { return i % 2 == 0 ? 1.0 : -1.0; }

// The simulated log with offsets o_i(t) = o_i + s_i kOffsetRate t and bias b(t) growing at the
// rates above (what the robot's torque sensing and the F/T sensor drift by).
std::vector<Sample> drifting_log(const Model& model, bool push) {
  std::vector<sim::ForceProfile> forces;
  if (push) forces.push_back(test::tangential_push(5, 15.0, kPushStart, kPushEnd));
  auto log = test::simulate_free_motion(model, test::free_motion(0.3, 1.0), offsets_only(),
                                        kDuration, initial_bias(), 0.01, 41, forces);
  for (Sample& s : log) {
    for (int i = 0; i < 7; ++i) s.tau[i] += drift_sign(i) * kOffsetRate * s.t;
    s.reading_S.head<3>().array() += kBiasForceRate * s.t;
    s.reading_S.tail<3>().array() += kBiasMomentRate * s.t;
  }
  return log;
}

EstimatorOptions options(bool drift) {
  EstimatorOptions o;
  o.sensor.type = SensorType::kForceTorque;
  o.sensor.bias_S = initial_bias();  // as a calibration at t = 0 would give
  JointFriction f = JointFriction::none(7);
  f.offset = offsets_only().offset;
  o.friction = f;
  o.detection.tau_min = VectorX::Constant(1, 0.3);
  o.detection.f_min = 2.0;
  if (drift) o.drift = DriftOptions{5.0, 0.02, 0.1, 0.01};
  return o;
}

TEST(DriftTracking, FollowsCreepingOffsetsAndBiasWithoutFalseAlarms) {
  const Model model = paper_arm();
  const auto log = drifting_log(model, false);
  for (const bool drift : {false, true}) {
    SCOPED_TRACE(drift ? "with drift tracking" : "without");
    ContactEstimator est(model, GeometryModel{}, options(drift));
    ASSERT_TRUE(est.reset(log.front()).ok());
    int alarms = 0;
    for (std::size_t k = 1; k < log.size(); ++k) {
      ASSERT_TRUE(est.update(log[k]).ok());
      if (est.result().contact) ++alarms;
    }
    std::printf("%s drift tracking: %d alarm samples of %zu\n", drift ? "with" : "without", alarms,
                log.size());
    if (!drift) {
      EXPECT_GT(alarms, 1000) << "the drift should exceed the thresholds without tracking";
      EXPECT_EQ(est.result().torque_offset.size(), 0);
      continue;
    }
    EXPECT_EQ(alarms, 0);
    const double t = log.back().t;
    const VectorX& offset = est.result().torque_offset;
    ASSERT_EQ(offset.size(), 7);
    for (int i = 0; i < 7; ++i) {
      const double truth = offsets_only().offset[i] + drift_sign(i) * kOffsetRate * t;
      std::printf("joint %d offset %.4f truth %.4f\n", i + 1, offset[i], truth);
      EXPECT_NEAR(offset[i], truth, 0.05) << "joint " << i + 1;  // drift 0.48 N m by the end
    }
    const Vector6& bias = est.result().sensor_bias_S;
    std::printf("bias %.3f %.3f %.3f %.4f %.4f %.4f at t = %.1f s\n", bias[0], bias[1], bias[2],
                bias[3], bias[4], bias[5], t);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(bias[a], initial_bias()[a] + kBiasForceRate * t, 0.3) << "axis " << a;  // 3.6 N
      EXPECT_NEAR(bias[3 + a], initial_bias()[3 + a] + kBiasMomentRate * t, 0.03) << "axis " << a;
    }
  }
}

TEST(DriftTracking, FrozenDuringContactAndThePushIsDetected) {
  const Model model = paper_arm();
  const auto log = drifting_log(model, true);
  ContactEstimator est(model, GeometryModel{}, options(true));
  ASSERT_TRUE(est.reset(log.front()).ok());
  double detected = -1.0;
  VectorX offset_at_onset;
  Vector6 bias_at_onset;
  int false_alarms = 0;
  for (std::size_t k = 1; k < log.size(); ++k) {
    ASSERT_TRUE(est.update(log[k]).ok());
    const double t = log[k].t;
    const ContactEstimate& e = est.result();
    if (e.contact && (t < kPushStart || t > kPushEnd + 0.2)) ++false_alarms;
    if (t >= kPushStart && e.contact && detected < 0) {
      detected = t - kPushStart;
      offset_at_onset = e.torque_offset;
      bias_at_onset = e.sensor_bias_S;
    }
    if (detected >= 0 && e.contact) {
      EXPECT_EQ(e.torque_offset, offset_at_onset) << "offsets moved during contact, t = " << t;
      EXPECT_EQ(e.sensor_bias_S, bias_at_onset) << "bias moved during contact, t = " << t;
    }
  }
  EXPECT_EQ(false_alarms, 0);
  EXPECT_GE(detected, 0.0);
  EXPECT_LE(detected, 0.05);
}

TEST(DriftTracking, ResetReturnsToTheConfiguredValues) {
  const Model model = paper_arm();
  const auto log = drifting_log(model, false);
  ContactEstimator est(model, GeometryModel{}, options(true));
  ContactEstimator fresh(model, GeometryModel{}, options(true));
  ASSERT_TRUE(est.reset(log.front()).ok());
  for (std::size_t k = 1; k < 20000; ++k) ASSERT_TRUE(est.update(log[k]).ok());
  ASSERT_NE(est.result().torque_offset, options(true).friction->offset);
  ASSERT_TRUE(est.reset(log[20000]).ok());
  ASSERT_TRUE(fresh.reset(log[20000]).ok());
  for (std::size_t k = 20001; k < 21000; ++k) {
    ASSERT_TRUE(est.update(log[k]).ok());
    ASSERT_TRUE(fresh.update(log[k]).ok());
    ASSERT_EQ(est.result().residual, fresh.result().residual) << "sample " << k;
    ASSERT_EQ(est.result().torque_offset, fresh.result().torque_offset) << "sample " << k;
  }
}

}  // namespace
}  // namespace extwrench
