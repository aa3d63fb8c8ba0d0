// The base sensor's small rules (estimation/base_sensor.hpp): the default pose, the reading
// check, the tare, and F̂ / n_m − ñ_g against the formulas (11), (13) written out.
#include <gtest/gtest.h>

#include <limits>

#include "extwrench/estimation/base_sensor.hpp"
#include "support/test_robots.hpp"

namespace extwrench {
namespace {

TEST(BaseSensor, DefaultPoseIsTheSensorFrameOnLinkZeroElseIdentity) {
  Model model = test::paper_arm_model();
  EXPECT_TRUE(default_sensor_pose(model).rotation.isIdentity(0.0));
  EXPECT_TRUE(default_sensor_pose(model).translation.isZero(0.0));
  const Pose X = Pose::from_xyz_rpy(Vector3(0.1, -0.2, 0.05), Vector3(0.3, 0.0, -0.4));
  model.frames.push_back({"sensor", 0, X});
  const Pose on_base = default_sensor_pose(model);
  EXPECT_EQ(on_base.rotation, X.rotation);
  EXPECT_EQ(on_base.translation, X.translation);
  model.frames.back().body = 3;  // on a moving body: not a base sensor
  EXPECT_TRUE(default_sensor_pose(model).rotation.isIdentity(0.0));
  EXPECT_TRUE(default_sensor_pose(model).translation.isZero(0.0));
}

TEST(BaseSensor, ReadingCheckLooksOnlyAtTheMeasuredEntries) {
  Vector6 r = Vector6::Zero();
  r[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(check_reading(SensorType::kNone, r).ok());
  EXPECT_TRUE(check_reading(SensorType::kForce, r).ok());
  const Status s = check_reading(SensorType::kForceTorque, r);
  EXPECT_EQ(s.code, StatusCode::kNonFinite);
  EXPECT_EQ(s.channel, Channel::kBaseWrench);
  EXPECT_EQ(s.index, 4);
}

TEST(BaseSensor, TareAveragesReadingMinusPredictionThenCorrectsEveryReading) {
  const Pose X_WS = Pose::from_xyz_rpy(Vector3(0.0, 0.0, -0.3), Vector3(0.2, -0.1, 0.5));
  const Vector6 bias = (Vector6() << 1.0, -2.0, 3.0, 0.1, -0.2, 0.3).finished();
  const Vector6 predicted_W = (Vector6() << 0.5, 0.2, -90.0, 1.0, -2.0, 0.1).finished();
  // The reading of a contact-free robot: the prediction in S plus the bias.
  Vector6 reading_S;
  reading_S.head<3>() = X_WS.rotation.transpose() * predicted_W.head<3>();
  reading_S.tail<3>() = X_WS.rotation.transpose() * predicted_W.tail<3>();
  reading_S += bias;
  SensorTare tare;
  tare.request(4);
  for (int k = 0; k < 4; ++k) {
    const BaseWrench w = base_wrench(SensorType::kForceTorque, X_WS, reading_S, predicted_W, tare);
    EXPECT_EQ(w.taring, k < 3) << "sample " << k;
  }
  EXPECT_FALSE(tare.active());
  EXPECT_LT((tare.bias_S - bias).norm(), 1e-12);
  // After the tare, a force F in W and a moment M about O_s come out as (11), (13).
  const Vector3 F(3.0, -4.0, 12.0), M(0.5, 0.25, -1.0);
  Vector6 touched = reading_S;
  touched.head<3>() += X_WS.rotation.transpose() * F;
  touched.tail<3>() += X_WS.rotation.transpose() * M;
  const BaseWrench w = base_wrench(SensorType::kForceTorque, X_WS, touched, predicted_W, tare);
  EXPECT_FALSE(w.taring);
  EXPECT_LT((w.force_W - F).norm(), 1e-9);
  EXPECT_LT((w.dn_W - M).norm(), 1e-9);
  // A force sensor has no moment entries: its bias and n_m − ñ_g stay out.
  SensorTare force_tare;
  force_tare.request(1);
  const BaseWrench f = base_wrench(SensorType::kForce, X_WS, reading_S, predicted_W, force_tare);
  EXPECT_FALSE(f.taring);
  EXPECT_TRUE(force_tare.bias_S.tail<3>().isZero(0.0));
  EXPECT_TRUE(f.dn_W.array().isNaN().all());
}

}  // namespace
}  // namespace extwrench
