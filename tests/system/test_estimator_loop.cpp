// The estimator in the loop (acceptance 2 of issue 3): the paper arm simulated with the core's
// forward dynamics (RK4, 1 kHz, torque held between samples), tracked by computed torque on a
// model with ±1 % parameter errors (paper Sec. IV), the estimator on that same perturbed model.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "extwrench/estimation/contact_estimator.hpp"
#include "support/test_robots.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

constexpr double kDt = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Scenario {
  SensorType sensor = SensorType::kForceTorque;
  ContactModel contact = ContactModel::kPureForce;
  AccelerationRoute route = AccelerationRoute::kResidual;
  double gain = 100.0;
  double param_error = 0.01;
  unsigned seed = 1;
  int link = -1;  ///< contact link (−1: free motion)
  Vector3 p_L = Vector3::Zero();
  Vector3 F_L = Vector3::Zero();  ///< constant in the link frame
  int link2 = -1;                 ///< optional second contact
  Vector3 p2_L = Vector3::Zero(), F2_L = Vector3::Zero();
  double t_on = 1.0, t_off = 2.5, t_end = 2.5;
  bool force_in_world = false;   ///< F_L is then constant in the world frame
  double speed = 1.0;            ///< scales the trajectory's frequencies
  double tau_min = 1.0;          ///< detection threshold (default of DetectionOptions)
  double kp = 100.0, kd = 20.0;  ///< the tracking controller's PD gains [1/s², 1/s]
  /// The contact points here are anywhere in the link frame, mostly off its capsules: the
  /// paper's rule (geometry isolation needs points on the surface: test_geometry_isolation).
  IsolationRule isolation = IsolationRule::kResidual;
  double armature = 0.0;  ///< rotor inertia on every joint of the true robot [kg m²]
  bool estimator_knows_armature = true;  ///< false: the controller and estimator model lack it
};

struct Sample {
  double t;
  bool in_contact;  // truth
  Vector3 F_true;   // world
  Vector3 p_true;   // world
  ContactEstimate e;
};

/// Runs the scenario and calls `visit` after every estimator update.
template <typename Visit>
void run(const Scenario& s, Visit&& visit) {
  Model nominal = test::paper_arm_model();
  for (std::size_t i = 1; i < nominal.joints.size(); ++i)
    nominal.joints[i].armature = s.armature / static_cast<double>(i);  // larger near the base
  Model perturbed = test::perturbed_model(nominal, s.param_error, s.seed);
  if (!s.estimator_knows_armature) {
    for (Joint& j : perturbed.joints) j.armature = 0.0;
  }
  test::SimulatedArm arm(nominal);
  Data ctrl(perturbed), truth(nominal);
  test::SineTracker tracker(7);
  tracker.amplitude = (VectorX(7) << 0.8, 0.6, 0.8, 0.7, 0.9, 0.8, 1.0).finished();
  tracker.q0 = (VectorX(7) << 0, 0.6, 0, -0.9, 0, 0.7, 0).finished();
  tracker.frequency *= s.speed;
  tracker.kp = s.kp;
  tracker.kd = s.kd;
  arm.q = tracker.q0;
  {
    VectorX qd, dqd, ddqd;
    tracker.desired(0.0, qd, dqd, ddqd);
    arm.dq = dqd;
  }
  bool on = false;
  auto wrenches = [&](const Data& d, ExternalWrench* w) {
    int k = 0;
    if (!on) return 0;
    const Vector3 F_W = s.force_in_world ? s.F_L : Vector3(d.X_WB[s.link].rotation * s.F_L);
    w[k++] = {s.link, F_W, d.X_WB[s.link].act(s.p_L), Vector3::Zero()};
    if (s.link2 >= 0)
      w[k++] = {s.link2, d.X_WB[s.link2].rotation * s.F2_L, d.X_WB[s.link2].act(s.p2_L),
                Vector3::Zero()};
    return k;
  };
  arm.external = [&](const Model& m, Data& d, double, const VectorX& q, const VectorX& dq,
                     VectorX& out) {
    forward_kinematics(m, d, q);
    ExternalWrench w[2];
    const int k = wrenches(d, w);
    if (k == 0) return;
    const VectorX zero = VectorX::Zero(m.nq());
    const VectorX free = rnea(m, d, q, dq, zero);
    out += free - rnea(m, d, q, dq, zero, std::span<const ExternalWrench>(w, k));
  };
  EstimatorOptions opt;
  opt.sensor.type = s.sensor;
  opt.contact.model = s.contact;
  opt.contact.link = s.link;
  opt.contact.point_L = s.p_L;
  opt.observer_gain = VectorX::Constant(1, s.gain);
  opt.acceleration = s.route;
  opt.detection.tau_min = VectorX::Constant(1, s.tau_min);
  opt.isolation.rule = s.isolation;
  ContactEstimator est(perturbed, test::paper_arm_capsules(perturbed), opt);
  VectorX tau = tracker.torque(perturbed, ctrl, 0.0, arm.q, arm.dq);
  ASSERT_TRUE(est.reset(0.0, arm.q, arm.dq, tau).ok());
  const int steps = static_cast<int>(std::lround(s.t_end / kDt));
  for (int k = 1; k <= steps; ++k) {
    arm.step(tau, kDt);
    on = s.link >= 0 && arm.t >= s.t_on - 1e-9 && arm.t < s.t_off - 1e-9;
    tau = tracker.torque(perturbed, ctrl, arm.t, arm.q, arm.dq);
    // The base reading of the true robot at this sample: true q̈ under τ, RNEA with the wrenches.
    const VectorX ddq = arm.acceleration(arm.t, arm.q, arm.dq, tau);
    forward_kinematics(nominal, truth, arm.q);
    ExternalWrench w[2];
    const int nw = wrenches(truth, w);
    rnea(nominal, truth, arm.q, arm.dq, ddq, std::span<const ExternalWrench>(w, nw));
    const Vector6 reading = sensor_reading(truth, Pose{});
    const Status st = s.sensor == SensorType::kNone
                          ? est.update(arm.t, arm.q, arm.dq, tau)
                          : est.update(arm.t, arm.q, arm.dq, tau, reading);
    ASSERT_TRUE(st.ok());
    Sample smp{arm.t, nw > 0, nw > 0 ? w[0].force_W : Vector3::Constant(kNaN),
               nw > 0 ? w[0].point_W : Vector3::Constant(kNaN), est.result()};
    visit(smp);
  }
}

Vector3 tangential_force(SeededRng& rng, const Vector3& lever_dir, double magnitude) {
  // Perpendicular to the lever and tilted at most 30° off the tangent of joint l's axis (body z),
  // so |τ_ext,l| ≥ |F| · lever · cos 30°.
  const Vector3 tangent = Vector3::UnitZ().cross(lever_dir).normalized();
  const double beta = rng.uniform(-0.5, 0.5);
  return magnitude * (std::cos(beta) * tangent + std::sin(beta) * Vector3::UnitZ());
}

// A constant (world-frame) force starts on a moving arm: the wrench error decays with e^{−K t}
// (eq. 5: ṙ = K (τ_ext − r)) and is < 1 % of ‖F‖ by 8/K s. The law holds for a constant
// τ_ext; on a moving arm τ_ext = J(q)ᵀ F drifts and r lags it by ≈ (1/K) dτ_ext/dt. So the arm
// is position-controlled stiffly (ω = 100 rad/s, like an industrial arm): with the soft default
// gains (ω = 10 rad/s) the push deflects the arm over ~0.3 s, τ_ext changes with q while the
// filter settles, and that transient of the simulated controller, not the observer, dominated
// (1.2–1.4 % at K = 50). The trajectory's own drift leaves ≈ 0.6 % at K = 50, 0.3 % at K = 100.
TEST(EstimatorLoop, ForceErrorDecaysLikeTheFirstOrderLawAndIsBelowOnePercentByEightOverK) {
  for (SensorType sensor : {SensorType::kNone, SensorType::kForceTorque}) {
    for (double gain : {50.0, 100.0, 200.0}) {
      Scenario s;
      s.sensor = sensor;
      s.gain = gain;
      s.param_error = 0.0;  // exact model
      s.speed = 0.15;
      s.link = 7;
      s.p_L = Vector3(0.15, 0.05, 0.05);
      s.F_L = Vector3(6, 15, -8);
      s.force_in_world = true;
      s.tau_min = 0.1;  // isolation must find link 7 (no sensor needs rank J_l = 6)
      s.t_on = 0.5;
      s.t_off = s.t_end = 0.5 + 8 / gain + 0.3;
      s.kp = 1e4;
      s.kd = 200;
      const double floor = 1e-2;  // the acceptance bound, for every K
      double err_first = kNaN, worst_late = 0.0, worst_law_excess = 0.0;
      run(s, [&](const Sample& m) {
        if (!m.in_contact) return;
        double err = (m.e.force_W - m.F_true).norm() / m.F_true.norm();
        const double since = m.t - s.t_on;
        if (std::isnan(err) && since >= 2 / gain) err = 1e9;  // no estimate: a failure, not a pass
        if (std::isnan(err_first) && since >= 1 / gain - 1e-9) err_first = err;
        if (since >= 1 / gain) {
          // e(t) ≤ e(1/K) e^{−K (t − 1/K)}, plus the 1 % allowed for the lag behind the drift
          // of τ_ext = J(q)ᵀ F (∝ speed / K)
          const double law = 1.3 * err_first * std::exp(-gain * (since - 1 / gain)) + floor;
          worst_law_excess = std::max(worst_law_excess, err - law);
        }
        if (since >= 8 / gain) worst_late = std::max(worst_late, err);
      });
      std::printf("%s K = %.0f: error at 1/K %.3f, max after 8/K %.4f (relative)\n",
                  std::string(to_string(sensor)).c_str(), gain, err_first, worst_late);
      EXPECT_LE(worst_law_excess, 0.0) << to_string(sensor) << " K = " << gain;
      EXPECT_GT(err_first, 0.2) << to_string(sensor)
                                << " K = " << gain;  // ≈ e^{−1}: the law, not a lucky start
      EXPECT_LT(worst_late, floor) << to_string(sensor) << " K = " << gain;
    }
  }
}

// Armature (reflected rotor inertia) on every joint of the simulated robot: an estimator whose
// model has it stays as exact as on a robot without (the bound of the test above at K = 100);
// one whose model lacks it sees I_a q̈ as an external torque.
TEST(EstimatorLoop, ArmatureOnEveryJointKeepsTheEstimateExactWhenTheModelHasIt) {
  for (const bool knows : {true, false}) {
    Scenario s;
    s.sensor = SensorType::kForceTorque;
    s.gain = 100.0;
    s.param_error = 0.0;
    s.armature = 0.5;  // 0.5, 0.25, ... 0.07 kg m² from joint 1 to 7
    s.estimator_knows_armature = knows;
    s.speed = 0.5;
    s.link = 7;
    s.p_L = Vector3(0.15, 0.05, 0.05);
    s.F_L = Vector3(6, 15, -8);
    s.force_in_world = true;
    s.tau_min = 0.1;
    s.t_on = 0.5;
    s.t_off = s.t_end = 1.5;
    s.kp = 1e4;
    s.kd = 200;
    double worst = 0.0;
    double worst_free = 0.0;  // |τ̂_ext| in free motion
    run(s, [&](const Sample& m) {
      if (m.t < 0.3) return;
      if (!m.in_contact) {
        worst_free = std::max(worst_free, m.e.residual.cwiseAbs().maxCoeff());
        return;
      }
      if (m.t - s.t_on < 8 / s.gain) return;
      const double err = (m.e.force_W - m.F_true).norm() / m.F_true.norm();
      worst = std::max(worst, std::isnan(err) ? 1e9 : err);
    });
    std::printf("armature, model %s it: relative force error %.2e, free-motion |tau_ext| %.2e\n",
                knows ? "with" : "without", worst, worst_free);
    if (knows) {
      EXPECT_LT(worst, 1e-2);  // measured 5.3e-3
    } else {
      EXPECT_GT(worst, 2e-2);  // the control: measured 4.2e-2
    }
  }
}

TEST(EstimatorLoop, NoFalseAlarmsOverSixtySecondsOfFreeMotionWithOnePercentParameterErrors) {
  for (SensorType sensor : {SensorType::kForceTorque, SensorType::kForce, SensorType::kNone}) {
    Scenario s;
    s.sensor = sensor;
    s.t_end = 60.0;
    s.seed = 7;
    int alarms = 0, pending = 0;
    double max_residual = 0, max_force = 0;
    run(s, [&](const Sample& m) {
      alarms += m.e.contact ? 1 : 0;
      pending += m.e.has(EstimateFlag::kPending) ? 1 : 0;
      max_residual = std::max(max_residual, m.e.residual.cwiseAbs().maxCoeff());
      if (sensor != SensorType::kNone) max_force = std::max(max_force, m.e.force_W.norm());
    });
    EXPECT_EQ(alarms, 0) << to_string(sensor);
    EXPECT_EQ(pending, 0) << to_string(sensor);
    RecordProperty(std::string("max_residual_") + std::string(to_string(sensor)),
                   std::to_string(max_residual));
    std::printf("%s: max |r| = %.3f N m, max |F| = %.3f N over 60 s of free motion\n",
                std::string(to_string(sensor)).c_str(), max_residual, max_force);
  }
}

TEST(EstimatorLoop, TenNewtonsOnAnyLinkTwoToSevenAreDetectedWithin50msAndIsolatedRight) {
  SeededRng rng(77);
  for (SensorType sensor : {SensorType::kForceTorque, SensorType::kNone}) {
    for (int link = 2; link <= 7; ++link) {
      for (int trial = 0; trial < 2; ++trial) {
        Scenario s;
        s.sensor = sensor;
        s.link = link;
        s.seed = 100 + link * 2 + trial;
        const double angle = rng.uniform(-3.1, 3.1), lever = rng.uniform(0.2, 0.3);
        const Vector3 lever_dir(std::cos(angle), std::sin(angle), 0);
        s.p_L = lever * lever_dir + Vector3(0, 0, rng.uniform(-0.1, 0.1));
        s.F_L = tangential_force(rng, lever_dir, 10.0);
        s.t_on = 1.0;
        s.t_off = s.t_end = 2.2;
        double detected = kNaN;
        int right = 0, total = 0;
        run(s, [&](const Sample& m) {
          if (!m.in_contact) return;
          if (std::isnan(detected) && m.e.contact) detected = m.t - s.t_on;
          if (m.t >= s.t_on + 0.05) {
            ++total;
            right += m.e.link == link ? 1 : 0;
          }
        });
        const std::string what = std::string(to_string(sensor)) + " link " + std::to_string(link);
        ASSERT_FALSE(std::isnan(detected)) << what;
        EXPECT_LE(detected, 0.05) << what;
        EXPECT_GT(right, 0.99 * total) << what << ": " << right << "/" << total;
      }
    }
  }
}

TEST(EstimatorLoop, DifferentiationRouteEstimatesTheWrenchOnceItsFilterSettled) {
  Scenario s;
  s.sensor = SensorType::kForceTorque;
  s.contact = ContactModel::kKnownPoint;
  s.route = AccelerationRoute::kDifferentiation;
  s.param_error = 0.0;
  s.link = 5;
  s.p_L = Vector3(0.06, 0.0, 0.2);
  s.F_L = Vector3(12, -5, 3);
  s.t_on = 0.5;
  s.t_off = s.t_end = 1.2;
  double worst = 0;
  int contact = 0, total = 0;
  run(s, [&](const Sample& m) {
    if (!m.in_contact || m.t < s.t_on + 0.1) return;
    ++total;
    contact += m.e.contact ? 1 : 0;
    worst = std::max(worst, (m.e.force_W - m.F_true).norm() / m.F_true.norm());
    EXPECT_TRUE(m.e.has(EstimateFlag::kMoment));
  });
  EXPECT_LT(worst, 0.02);
  EXPECT_EQ(contact, total);
}

TEST(EstimatorLoop, TwoSimultaneousContactsRaiseTheDisagreementFlagAndOneDoesNot) {
  for (bool two : {false, true}) {
    Scenario s;
    s.sensor = SensorType::kForceTorque;
    s.param_error = 0.0;
    s.link = 6;
    s.p_L = Vector3(0.2, 0.0, 0.0);
    s.F_L = Vector3(0, 15, 0);
    if (two) {
      s.link2 = 3;
      s.p2_L = Vector3(0.0, 0.1, 0.2);
      s.F2_L = Vector3(10, 0, 0);
    }
    s.t_on = 0.5;
    s.t_off = s.t_end = 1.2;
    int flagged = 0, total = 0;
    run(s, [&](const Sample& m) {
      if (!m.in_contact || m.t < s.t_on + 0.1) return;
      ++total;
      flagged += m.e.has(EstimateFlag::kDisagreement) ? 1 : 0;
    });
    if (two) {
      EXPECT_EQ(flagged, total);
    } else {
      EXPECT_EQ(flagged, 0);
    }
  }
}

// Issue 9, acceptance 4: with a base sensor the contact ends with the sensor's force, ≤ 5 ms after
// the push ends (min_duration, or sensor_release_duration once the force with q̈ measured agrees),
// where the residual alone took 5–36 ms to decay below its release level. Exact model and ±1 %
// parameter errors.
TEST(EstimatorLoop, WithABaseSensorTheContactIsReleasedWithinFiveMillisecondsOfTheForceEnding) {
  SeededRng rng(91);
  double worst = 0.0;
  for (SensorType sensor : {SensorType::kForceTorque, SensorType::kForce}) {
    for (double error : {0.0, 0.01}) {
      for (int link : {3, 5, 7}) {
        Scenario s;
        s.sensor = sensor;
        s.param_error = error;
        s.link = link;
        s.seed = 300 + link;
        const double angle = rng.uniform(-3.1, 3.1), lever = rng.uniform(0.1, 0.2);
        const Vector3 lever_dir(std::cos(angle), std::sin(angle), 0);
        s.p_L = lever * lever_dir + Vector3(0, 0, rng.uniform(-0.05, 0.05));
        s.F_L = tangential_force(rng, lever_dir, 15.0);
        s.t_on = 0.5;
        s.t_off = 0.8;
        s.t_end = 0.9;
        double released = kNaN, residual_at_release = 0.0;
        int declared_before = 0, late_contact = 0;
        run(s, [&](const Sample& m) {
          if (m.in_contact && m.t > s.t_off - 0.05) {
            ++late_contact;
            declared_before += m.e.contact ? 1 : 0;
          }
          if (m.t >= s.t_off - 1e-9 && std::isnan(released) && !m.e.contact) {
            released = m.t - s.t_off;
            residual_at_release = m.e.residual.cwiseAbs().maxCoeff();
          }
          if (!std::isnan(released)) {
            EXPECT_FALSE(m.e.contact) << "declared again at " << m.t;
          }
        });
        const std::string what = std::string(to_string(sensor)) + " link " + std::to_string(link) +
                                 " error " + std::to_string(error);
        EXPECT_EQ(declared_before, late_contact) << what;  // the push was held to its end
        ASSERT_FALSE(std::isnan(released)) << what;
        std::printf("%s: released %.1f ms after the force ended, max |r| then %.2f N m\n",
                    what.c_str(), 1e3 * released, residual_at_release);
        EXPECT_LE(released, 0.005 + 1e-9) << what;
        worst = std::max(worst, released);
      }
    }
  }
  RecordProperty("worst_release_ms", std::to_string(1e3 * worst));
}

}  // namespace
}  // namespace extwrench
