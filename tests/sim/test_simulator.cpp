// The closed-loop simulator checked against physics: energy balance, the RNEA path, RK4's order,
// force profiles, sensor models, the perturbed model and the controller's tracking.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "calibration/calibration_sim.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/model/sample_models.hpp"
#include "extwrench/sim/metrics.hpp"
#include "extwrench/sim/perturb.hpp"
#include "extwrench/sim/simulator.hpp"
#include "support/random.hpp"

namespace extwrench::sim {
namespace {

using test::SeededRng;

// RK4 at 1e-3 s on these arms: local error ~ h^5 · (rate)^5 ~ 1e-12 per step.
constexpr double kEnergyTol = 1e-6;
// Algebraic identities that only reorder floating-point operations.
constexpr double kAlgebraicTol = 1e-9;

double kinetic_energy(const Model& model, Data& data, const VectorX& q, const VectorX& dq) {
  crba(model, data, q);
  return 0.5 * dq.dot(data.M * dq);
}

double potential_energy(const Model& model, Data& data, const VectorX& q) {
  forward_kinematics(model, data, q);
  double u = 0.0;
  for (int i = 0; i < model.num_bodies(); ++i) u -= model.gravity.dot(data.first_moment_W[i]);
  return u;
}

TEST(Rk4, ConservesTheEnergyOfAnUnactuatedArm) {
  const Model model = random_chain({.n = 7, .seed = 3});
  Rk4Workspace ws(model);
  Data data(model);
  SeededRng rng(5);
  VectorX q = rng.uniform_vector(7, -1, 1);
  VectorX dq = rng.uniform_vector(7, -1, 1);
  const VectorX tau = VectorX::Zero(7);
  const double e0 = kinetic_energy(model, data, q, dq) + potential_energy(model, data, q);
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(rk4_step(model, {}, k * 1e-3, 1e-3, tau, q, dq, ws));
  const double e1 = kinetic_energy(model, data, q, dq) + potential_energy(model, data, q);
  EXPECT_NEAR(e1, e0, kEnergyTol * std::max(1.0, std::abs(e0)));
}

TEST(Rk4, EnergyChangeEqualsTheWorkOfTorquesAndExternalForces) {
  const Model model = random_chain({.n = 5, .seed = 8});
  std::vector<ForceProfile> forces(1);
  forces[0].frame = "link4";
  forces[0].axes = ForceProfile::Axes::kWorld;
  forces[0].force = Vector3(3.0, -2.0, 5.0);
  forces[0].moment = Vector3(0.2, 0.1, -0.3);
  forces[0].point_F = Vector3(0.05, 0.0, 0.1);
  forces[0].resolve(model);
  Rk4Workspace ws(model);
  Data data(model);
  SeededRng rng(9);
  VectorX q = rng.uniform_vector(5, -1, 1);
  VectorX dq = rng.uniform_vector(5, -0.5, 0.5);
  const VectorX tau = rng.uniform_vector(5, -2, 2);
  const double h = 1e-4;
  const double e0 = kinetic_energy(model, data, q, dq) + potential_energy(model, data, q);
  // dE/dt = q̇ᵀ (τ + τ_ext): integrate the power with the trapezoidal rule (error O(h²)).
  auto power = [&](double t, const VectorX& qq, const VectorX& vv) {
    EXPECT_TRUE(true_acceleration(model, forces, t, qq, vv, tau, ws));
    return vv.dot(tau + ws.tau_ext);
  };
  double work = 0.0;
  double p_prev = power(0.0, q, dq);
  for (int k = 0; k < 2000; ++k) {
    ASSERT_TRUE(rk4_step(model, forces, k * h, h, tau, q, dq, ws));
    const double p = power((k + 1) * h, q, dq);
    work += 0.5 * h * (p_prev + p);
    p_prev = p;
  }
  const double e1 = kinetic_energy(model, data, q, dq) + potential_energy(model, data, q);
  EXPECT_NEAR(e1 - e0, work, 1e-5 * std::max(1.0, std::abs(work)));
}

TEST(Rk4, ErrorShrinksWithTheFourthPowerOfTheStep) {
  const Model model = random_chain({.n = 4, .seed = 2});
  Rk4Workspace ws(model);
  SeededRng rng(4);
  const VectorX q0 = rng.uniform_vector(4, -1, 1);
  const VectorX dq0 = rng.uniform_vector(4, -1, 1);
  const VectorX tau = rng.uniform_vector(4, -1, 1);
  auto run = [&](int steps) {
    VectorX q = q0, dq = dq0;
    const double h = 0.2 / steps;
    for (int k = 0; k < steps; ++k) EXPECT_TRUE(rk4_step(model, {}, k * h, h, tau, q, dq, ws));
    return q;
  };
  const VectorX reference = run(1280);
  const double e1 = (run(10) - reference).norm();
  const double e2 = (run(20) - reference).norm();
  // Global error O(h^4): halving h divides it by 16 (a margin for the asymptotic regime).
  EXPECT_GT(e1 / e2, 12.0);
  EXPECT_LT(e1 / e2, 20.0);
}

TEST(Simulator, TrueAccelerationSatisfiesInverseDynamicsWithTheExternalWrench) {
  const Model model = random_chain({.n = 7, .seed = 12});
  std::vector<ForceProfile> forces(2);
  forces[0].frame = "link6";
  forces[0].force = Vector3(20, 0, 0);
  forces[0].point_F = Vector3(0, 0, 0.1);
  forces[1].frame = "link3";
  forces[1].axes = ForceProfile::Axes::kWorld;
  forces[1].force = Vector3(0, -4, 1);
  forces[1].moment = Vector3(0.5, 0, 0);
  for (auto& f : forces) f.resolve(model);
  Rk4Workspace ws(model);
  Data data(model);
  SeededRng rng(13);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorX q = rng.uniform_vector(7, -2, 2);
    const VectorX dq = rng.uniform_vector(7, -1, 1);
    const VectorX tau = rng.uniform_vector(7, -5, 5);
    ASSERT_TRUE(true_acceleration(model, forces, 0.0, q, dq, tau, ws));
    // RNEA with the wrenches (eqs. 7-12) at the simulated q̈ must give back τ.
    const VectorX tau_back = rnea(model, data, q, dq, ws.data.ddq, ws.wrenches);
    EXPECT_LT((tau_back - tau).cwiseAbs().maxCoeff(),
              kAlgebraicTol * (1.0 + tau.cwiseAbs().maxCoeff()));
    // τ_ext from the point Jacobians equals the RNEA difference.
    const VectorX zero = VectorX::Zero(7);
    const VectorX free = rnea(model, data, q, dq, zero);
    const VectorX loaded = rnea(model, data, q, dq, zero, ws.wrenches);
    EXPECT_LT((free - loaded - ws.tau_ext).cwiseAbs().maxCoeff(), kAlgebraicTol * 10);
  }
}

TEST(ForceProfile, RampsUpAndDownInsideItsWindow) {
  ForceProfile f;
  f.start = 1.0;
  f.end = 3.0;
  f.ramp = 0.5;
  EXPECT_EQ(f.scale(0.99), 0.0);
  EXPECT_DOUBLE_EQ(f.scale(1.25), 0.5);
  EXPECT_DOUBLE_EQ(f.scale(2.0), 1.0);
  EXPECT_DOUBLE_EQ(f.scale(2.75), 0.5);
  EXPECT_EQ(f.scale(3.01), 0.0);
  f.ramp = 0.0;
  EXPECT_EQ(f.scale(1.0), 1.0);
}

TEST(ForceProfile, FrameForceTurnsWithTheLinkAndWorldForceDoesNot) {
  const Model model = random_chain({.n = 3, .seed = 21});
  Data data(model);
  forward_kinematics(model, data, VectorX::Constant(3, 0.7));
  ForceProfile in_frame;
  in_frame.frame = "link2";
  in_frame.force = Vector3(1, 2, 3);
  in_frame.point_F = Vector3(0.1, 0.2, 0.3);
  in_frame.resolve(model);
  ForceProfile in_world = in_frame;
  in_world.axes = ForceProfile::Axes::kWorld;
  ExternalWrench a, b;
  ASSERT_TRUE(in_frame.evaluate(0.0, data, a));
  ASSERT_TRUE(in_world.evaluate(0.0, data, b));
  const Pose& X_WB = data.X_WB[2];
  EXPECT_TRUE(a.force_W.isApprox(X_WB.rotation * Vector3(1, 2, 3), 1e-14));
  EXPECT_TRUE(b.force_W.isApprox(Vector3(1, 2, 3), 1e-14));
  EXPECT_TRUE(a.point_W.isApprox(X_WB.act(Vector3(0.1, 0.2, 0.3)), 1e-14));
  EXPECT_EQ(a.body, 2);
}

TEST(ForceProfile, UnknownFrameIsAnErrorNamingIt) {
  const Model model = random_chain({.n = 2, .seed = 1});
  ForceProfile f;
  f.frame = "tool0";
  try {
    f.resolve(model);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'tool0'"), std::string::npos);
  }
}

TEST(SensorModel, QuantizesToTheEncoderResolution) {
  EncoderModel enc{.resolution = 1e-3};
  EXPECT_DOUBLE_EQ(enc.quantize(0.12345), 0.123);
  EXPECT_DOUBLE_EQ(enc.quantize(-0.0006), -0.001);
  EXPECT_EQ(EncoderModel{}.quantize(0.12345), 0.12345);
}

TEST(SensorModel, DifferentiatedVelocityOfARampIsItsSlope) {
  JointSensor js(EncoderModel{.differentiate = true}, 2);
  VectorX q(2), dq(2), qm(2), dqm(2);
  for (int k = 0; k < 5; ++k) {
    const double t = 0.002 * k;
    q << 0.5 * t, -2.0 * t;
    dq << 99, 99;  // the exact velocity must not be used after the first sample
    js.measure(t, q, dq, qm, dqm);
  }
  EXPECT_NEAR(dqm[0], 0.5, 1e-12);
  EXPECT_NEAR(dqm[1], -2.0, 1e-12);
}

TEST(SensorModel, NoiseHasTheConfiguredBiasAndStandardDeviation) {
  BaseSensorModel s;
  s.bias_S << 1, 2, 3, 0.1, 0.2, 0.3;
  s.force_noise_S = Vector3(0.5, 0.5, 0.5);
  s.moment_noise_S = Vector3(0.05, 0.05, 0.05);
  Rng rng(7);
  const int kDraws = 40000;
  Vector6 sum = Vector6::Zero(), sum_sq = Vector6::Zero();
  for (int k = 0; k < kDraws; ++k) {
    const Vector6 r = s.measure(Vector6::Zero(), rng) - s.bias_S;
    sum += r;
    sum_sq += r.cwiseProduct(r);
  }
  const Vector6 mean = sum / kDraws;
  const Vector6 sd = (sum_sq / kDraws).cwiseSqrt();
  for (int k = 0; k < 6; ++k) {
    const double sigma = k < 3 ? 0.5 : 0.05;
    // 5 standard errors of the mean and of the standard deviation.
    EXPECT_NEAR(mean[k], 0.0, 5 * sigma / std::sqrt(kDraws));
    EXPECT_NEAR(sd[k], sigma, 5 * sigma / std::sqrt(2.0 * kDraws));
  }
}

// sim::perturb_model: tests/sim/test_perturb.cpp.

SinusoidalTrajectory small_sinusoid(int n) {
  SinusoidalTrajectory tr;
  tr.offset = VectorX::Constant(n, 0.3);
  tr.amplitude = VectorX::Constant(n, 0.4);
  tr.frequency = VectorX::LinSpaced(n, 0.2, 0.5);
  tr.phase = VectorX::Zero(n);
  return tr;
}

TEST(Controller, ComputedTorqueWithTheExactModelTracksTheTrajectory) {
  const Model model = random_chain({.n = 6, .seed = 40});
  ComputedTorqueController ctl(model, small_sinusoid(6), pid_gains_triple_pole(6, 20.0));
  SimulationConfig cfg;
  cfg.duration = 1.0;
  cfg.q0 = VectorX::Constant(6, 0.35);  // start off the trajectory
  Simulator sim(model, ctl, cfg);
  Sample s;
  double first_error = 0.0, last_error = 0.0;
  VectorX qd(6), dqd(6), ddqd(6);
  while (sim.next(s)) {
    small_sinusoid(6).evaluate(s.t, qd, dqd, ddqd);
    const double e = (qd - s.q).cwiseAbs().maxCoeff();
    if (s.t == 0.0) first_error = e;
    last_error = e;
  }
  EXPECT_EQ(sim.num_samples(), 1001);
  EXPECT_NEAR(first_error, 0.05, 1e-12);
  EXPECT_LT(last_error, 1e-4);
}

// The logged joint torques carry the friction the drives overcome, offsets and noise
// (JointTorqueModel); the motion, the truth and the base sensor's noise stream stay exactly those
// of the run without them, and the logged τ minus the command is D q̇ + F_c tanh(q̇ / v_s) + o of
// the true q̇ (with exact encoders, the logged one) plus noise of the configured spread.
TEST(Simulator, JointTorqueModelAddsFrictionOffsetsAndNoiseToTheLogOnly) {
  const int n = 4;
  const Model model = random_chain({.n = n, .seed = 42});
  SimulationConfig plain;
  plain.duration = 2.0;
  plain.sensor.force_noise_S = Vector3::Constant(0.1);
  plain.noise_seed = 7;
  SimulationConfig with = plain;
  JointFriction& jt = with.joint_torque.friction.emplace(JointFriction::none(n));
  jt.sign = SmoothSign::kTanh;
  jt.viscous = VectorX::LinSpaced(n, 0.2, 0.5);
  jt.coulomb = VectorX::LinSpaced(n, 0.3, 0.9);
  jt.smoothing_velocity = 0.05;
  jt.offset = VectorX::LinSpaced(n, -0.1, 0.2);
  const auto gains = pid_gains_triple_pole(n, 20.0);
  Simulator a(model, ComputedTorqueController(model, small_sinusoid(n), gains), plain);
  Simulator b(model, ComputedTorqueController(model, small_sinusoid(n), gains), with);
  Sample sa, sb;
  while (a.next(sa)) {
    ASSERT_TRUE(b.next(sb));
    ASSERT_EQ(sa.q, sb.q);
    ASSERT_EQ(sa.reading_S, sb.reading_S);
    for (int i = 0; i < n; ++i) {
      const double friction = jt.viscous[i] * sa.dq[i] +
                              jt.coulomb[i] * std::tanh(sa.dq[i] / jt.smoothing_velocity) +
                              jt.offset[i];
      ASSERT_NEAR(sb.tau[i] - sa.tau[i], friction, 1e-12) << "joint " << i + 1 << " t " << sa.t;
    }
  }
  // The Dahl sign: its state from zero, advanced by the true Δq (exact encoders: the logged q),
  // against an explicit Euler integration of dz/dq = (sign(Δq) − z) / δ.
  SimulationConfig dahl = plain;
  JointFriction& jd = dahl.joint_torque.friction.emplace(jt);
  jd.sign = SmoothSign::kDahl;
  jd.presliding = VectorX::Constant(n, 0.003);
  Simulator e(model, ComputedTorqueController(model, small_sinusoid(n), gains), plain);
  Simulator g(model, ComputedTorqueController(model, small_sinusoid(n), gains), dahl);
  VectorX z = VectorX::Zero(n), q_prev(n);
  bool first = true;
  while (e.next(sa)) {
    ASSERT_TRUE(g.next(sb));
    for (int i = 0; i < n; ++i) {
      // 20 × 200 Euler steps a sample: their own error stays well below the tolerance.
      for (int part = 0; part < 20 && !first; ++part)
        z[i] = test::dahl_euler(z[i], (sa.q[i] - q_prev[i]) / 20.0, 0.003);
      const double friction = jd.viscous[i] * sa.dq[i] + jd.coulomb[i] * z[i] + jd.offset[i];
      // A sign of q̇ instead of the state would be F_c (0.3–0.9 N m) off after each reversal.
      ASSERT_NEAR(sb.tau[i] - sa.tau[i], friction, 1e-4) << "joint " << i + 1 << " t " << sa.t;
    }
    q_prev = sa.q;
    first = false;
  }
  // Noise only: zero mean, each joint's own spread (0.02, 0.04, ... N m), one quiet joint.
  SimulationConfig noisy = plain;
  noisy.joint_torque.noise = VectorX::LinSpaced(n, 0.02, 0.02 * n);
  noisy.joint_torque.noise[n - 1] = 0.0;
  Simulator c(model, ComputedTorqueController(model, small_sinusoid(n), gains), plain);
  Simulator d(model, ComputedTorqueController(model, small_sinusoid(n), gains), noisy);
  VectorX sum = VectorX::Zero(n), sum2 = VectorX::Zero(n);
  double count = 0;
  while (c.next(sa)) {
    ASSERT_TRUE(d.next(sb));
    const VectorX e = sb.tau - sa.tau;
    sum += e;
    sum2 += e.cwiseProduct(e);
    count += 1;
  }
  for (int i = 0; i < n; ++i) {
    const double mean = sum[i] / count, sd = std::sqrt(sum2[i] / count - mean * mean);
    const double sigma = noisy.joint_torque.noise[i];
    EXPECT_NEAR(mean, 0.0, 5 * sigma / std::sqrt(count) + 1e-12) << "joint " << i + 1;
    EXPECT_NEAR(sd, sigma, 5 * sigma / std::sqrt(2 * count) + 1e-12) << "joint " << i + 1;
  }
  SimulationConfig wrong_size = plain;
  wrong_size.joint_torque.noise = VectorX::Constant(n - 1, 0.05);
  EXPECT_THROW(
      Simulator(model, ComputedTorqueController(model, small_sinusoid(n), gains), wrong_size),
      Error);
  // Bad coefficients name what is wrong.
  SimulationConfig bad = plain;
  bad.joint_torque.friction = JointFriction::none(n);
  bad.joint_torque.friction->viscous = VectorX::Constant(n + 1, 0.1);
  EXPECT_THROW(Simulator(model, ComputedTorqueController(model, small_sinusoid(n), gains), bad),
               Error);
  bad = plain;
  bad.joint_torque.friction = JointFriction::none(n);
  bad.joint_torque.friction->coulomb = VectorX::Constant(n, -0.1);
  try {
    Simulator s(model, ComputedTorqueController(model, small_sinusoid(n), gains), bad);
    FAIL() << "a negative Coulomb friction was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("joint_torque: friction.coulomb[0]"), std::string::npos)
        << e.what();
  }
}

TEST(Controller, IntegralTermRecoversThePathUnderAConstantForce) {
  // A set point and a world-frame force: the disturbance is constant in joint space, so the
  // integral term must bring the error back to zero (the paper's "recovers the path").
  const Model model = random_chain({.n = 6, .seed = 41});
  SinusoidalTrajectory tr = small_sinusoid(6);
  tr.amplitude.setZero();
  ComputedTorqueController ctl(perturb_model(model, 0.01, 3), tr, pid_gains_triple_pole(6, 10.0));
  SimulationConfig cfg;
  cfg.duration = 3.0;
  cfg.forces.resize(1);
  cfg.forces[0].frame = "link6";
  cfg.forces[0].axes = ForceProfile::Axes::kWorld;
  cfg.forces[0].force = Vector3(20, 0, 0);
  cfg.forces[0].point_F = Vector3(0, 0, 0.1);
  cfg.forces[0].start = 0.5;
  Simulator sim(model, ctl, cfg);
  Sample s;
  double peak = 0.0, last = 0.0;
  VectorX qd(6), dqd(6), ddqd(6);
  while (sim.next(s)) {
    tr.evaluate(s.t, qd, dqd, ddqd);
    last = (qd - s.q).cwiseAbs().maxCoeff();
    peak = std::max(peak, last);
    if (s.t >= 0.5) {
      EXPECT_EQ(s.truth.link, "link6");
      EXPECT_NEAR(s.truth.force_W.norm(), 20.0, 1e-9);
    } else {
      EXPECT_EQ(s.truth.link, "");
    }
  }
  EXPECT_GT(peak, 1e-3);
  EXPECT_LT(last, 0.01 * peak);
}

// The log's t is the decimal a person expects: at 1 kHz sample 9 is at 0.009, not at
// 9 × 0.001 = 0.009000000000000001 (14 % of a minute's rows were written so). A rate that is not a
// whole number of hertz keeps k · sample_time.
TEST(Simulator, SampleInstantsAreTheDecimalsOfAWholeRate) {
  const Model model = random_chain({.n = 3, .seed = 51});
  SinusoidalTrajectory tr = small_sinusoid(3);
  ComputedTorqueController ctl(model, tr, pid_gains_triple_pole(3, 10.0));
  SimulationConfig cfg;
  cfg.duration = 1.0;
  Simulator sim(model, ctl, cfg);
  Sample s;
  long k = 0;
  while (sim.next(s)) {
    char decimal[32];
    std::snprintf(decimal, sizeof decimal, "%ld.%03ld", k / 1000, k % 1000);
    ASSERT_EQ(s.t, std::strtod(decimal, nullptr)) << decimal;
    ++k;
  }
  EXPECT_EQ(k, 1001);
  EXPECT_EQ(sample_instant(9, 0.0007), 9 * 0.0007);  // 1428.57... Hz
  EXPECT_EQ(sample_instant(3, 0.002), 0.006);        // 500 Hz
}

TEST(Simulator, BaseReadingEqualsWeightPlusForceForARobotHeldAtRest) {
  // Exact model, zero gains, zero trajectory speed: the computed torque balances gravity, and
  // a world-frame force balanced by nothing accelerates the arm; at t = 0 with q̇ = 0 the reading
  // is f_m = m g⃗ + F − Σ m_i a_ci. Check the force part with a force on link 0, which does not
  // move the arm: f_m = m g⃗ + F exactly.
  const Model model = random_chain({.n = 3, .seed = 50});
  SinusoidalTrajectory tr = small_sinusoid(3);
  tr.amplitude.setZero();
  ComputedTorqueController ctl(model, tr, pid_gains_triple_pole(3, 10.0));
  SimulationConfig cfg;
  cfg.duration = 0.01;
  cfg.forces.resize(1);
  cfg.forces[0].frame = "link0";
  cfg.forces[0].axes = ForceProfile::Axes::kWorld;
  cfg.forces[0].force = Vector3(1, -2, 30);
  Simulator sim(model, ctl, cfg);
  Sample s;
  while (sim.next(s)) {
    const Vector3 expected = model.total_mass() * model.gravity + Vector3(1, -2, 30);
    EXPECT_LT((s.reading_S.head<3>() - expected).norm(), 1e-8);
    EXPECT_LT(s.truth.tau_ext.norm(), 1e-12);  // Remark: a contact on link 0 has no residual
  }
}

TEST(Metrics, AccumulatesErrorsInsideTheWindowOnly) {
  MetricsAccumulator acc(MetricsWindow{.from = 1.0, .to = 3.0, .exclude = {{1.5, 2.0}}});
  Truth truth;
  truth.body = 4;
  truth.contacts = 1;
  truth.force_W = Vector3(10, 0, 0);
  truth.point_W = Vector3(0, 0, 1);
  ContactEstimate est;
  est.contact = true;
  est.link = 4;
  est.flags = EstimateFlag::kContact | EstimateFlag::kForce | EstimateFlag::kLineOfAction;
  est.force_W = Vector3(13, 4, 0);  // error 5
  est.line_point_W = Vector3(0.5, 0, 0);
  est.line_direction_W = Vector3(0, 0, 1);  // distance 0.5
  for (int k = 0; k <= 40; ++k) {
    const double t = 0.1 * k;
    ContactEstimate e = est;
    if (t > 2.45 && t < 2.55) e.link = 3;  // one wrong link
    acc.add(t, truth, e);
  }
  const Metrics m = acc.result();
  // Samples 1.0..1.4 and 2.1..3.0 : 5 + 10 = 15.
  EXPECT_EQ(m.samples, 15);
  EXPECT_DOUBLE_EQ(m.force.rms(), 5.0);
  EXPECT_DOUBLE_EQ(m.line.max, 0.5);
  EXPECT_EQ(m.right_link, 14);
  EXPECT_EQ(m.onsets, 1);
  EXPECT_DOUBLE_EQ(m.delay_max, 0.0);
}

TEST(Metrics, CountsFalseAlarmsMissesAndDetectionDelay) {
  MetricsAccumulator acc(MetricsWindow{});
  Truth free_truth;  // body -1: free
  Truth contact;
  contact.body = 2;
  contact.contacts = 1;
  contact.force_W = Vector3(0, 0, 3);
  ContactEstimate none, alarm;
  alarm.contact = true;
  alarm.link = 2;
  alarm.flags = EstimateFlag::kContact | EstimateFlag::kForce;
  alarm.force_W = Vector3(0, 0, 3);
  acc.add(0.0, free_truth, alarm);  // false alarm, error 3
  acc.add(0.1, contact, none);      // onset, missed, error 3
  acc.add(0.2, contact, none);      // missed
  acc.add(0.3, contact, alarm);     // detected after 0.2 s, error 0
  const Metrics m = acc.result();
  EXPECT_EQ(m.false_alarms, 1);
  EXPECT_EQ(m.missed, 2);
  EXPECT_EQ(m.onsets_detected, 1);
  EXPECT_NEAR(m.delay_max, 0.2, 1e-15);
  EXPECT_NEAR(m.force.max, 3.0, 1e-15);
  EXPECT_NEAR(m.isolation_accuracy(), 1.0 / 3.0, 1e-15);
}

// Found by a review of the tuning workflow: a scheme always in contact had the best delay (0), the
// release after a push counted as alarms alone, and a pure-force scheme reported a moment error
// made of its undetected samples only.
TEST(Metrics, TellsTheReleaseFromAlarmsAndMeasuresNoDelayForAContactAlreadyDeclared) {
  MetricsAccumulator acc(MetricsWindow{});
  Truth free_truth, contact;
  contact.body = 2;
  contact.contacts = 1;
  contact.force_W = Vector3(0, 0, 3);
  contact.moment_W = Vector3(0, 2, 0);
  ContactEstimate none, declared;
  declared.contact = true;
  declared.link = 2;
  declared.flags = EstimateFlag::kContact | EstimateFlag::kForce;  // no moment estimated
  declared.force_W = Vector3(0, 0, 3);
  acc.add(0.0, free_truth, none);
  acc.add(0.1, contact, none);         // onset 1, missed
  acc.add(0.2, contact, declared);     // detected after 0.1 s
  acc.add(0.3, free_truth, declared);  // release
  acc.add(0.4, free_truth, declared);  // release
  acc.add(0.5, free_truth, none);      // released
  acc.add(0.6, free_truth, declared);  // a new alarm, not the release
  acc.add(0.7, contact, declared);     // onset 2: already declared, no delay
  acc.add(0.8, free_truth, none);
  Metrics m = acc.result();
  EXPECT_EQ(m.onsets, 2);
  EXPECT_EQ(m.onsets_detected, 1);
  EXPECT_EQ(m.onsets_already_declared, 1);
  EXPECT_NEAR(m.mean_detection_delay(), 0.1, 1e-15);
  EXPECT_EQ(m.false_alarms, 3);
  EXPECT_EQ(m.false_alarms_release, 2);
  EXPECT_EQ(m.moment.count, 0);  // the configuration estimates no moment
  // One estimated moment: the undetected samples count too (M̂ = 0 there).
  declared.flags |= EstimateFlag::kMoment;
  declared.moment_W = Vector3(0, 2, 0);
  acc.add(0.9, contact, declared);
  m = acc.result();
  EXPECT_EQ(m.moment.count, 5);           // 0.9, and the four samples without a declared contact
  EXPECT_NEAR(m.moment.max, 2.0, 1e-15);  // onset 1's missed sample: ‖M‖
}

TEST(Metrics, CountsTheForcesWithinTwoSigmaAndTheLargeErrorsLeftUnflagged) {
  MetricsAccumulator acc(MetricsWindow{});
  Truth contact;
  contact.body = 2;
  contact.contacts = 1;
  contact.force_W = Vector3(0, 0, 10);
  ContactEstimate e;
  e.contact = true;
  e.link = 2;
  e.flags = EstimateFlag::kContact | EstimateFlag::kForce;
  e.sigma_force = 1.0;
  e.force_W = Vector3(0, 0, 11);  // within 2σ
  acc.add(0.0, contact, e);
  e.force_W = Vector3(0, 0, 16);  // 6σ off, more than 50 % of ‖F‖, not flagged
  acc.add(0.1, contact, e);
  e.flags |= EstimateFlag::kUncertain;  // the same, flagged
  acc.add(0.2, contact, e);
  e.sigma_force = ContactEstimate::kNaN;  // no σ: not counted
  acc.add(0.3, contact, e);
  const Metrics m = acc.result();
  EXPECT_EQ(m.sigma_samples, 3);
  EXPECT_EQ(m.force_within_two_sigma, 1);
  EXPECT_EQ(m.uncertain, 1);
  EXPECT_EQ(m.large_force_error_unflagged, 1);
  EXPECT_NEAR(m.force_two_sigma_coverage(), 1.0 / 3.0, 1e-15);
}

}  // namespace
}  // namespace extwrench::sim
