// The momentum residual (eq. 4, docs/estimator.md) on a simulated arm (RK4 of the core's forward
// dynamics): the first-order law, uniform and non-uniform steps, friction, payload, bad inputs
// and allocations.
#include <gtest/gtest.h>

#include <cmath>

#include "extwrench/core/error.hpp"
#include "extwrench/observer/momentum_observer.hpp"
#include "support/alloc_counter.hpp"
#include "support/test_robots.hpp"

namespace extwrench {
namespace {

using test::SeededRng;
using test::SimulatedArm;
using test::SineTracker;

constexpr double kDt = 1e-3;

// A moving arm under computed torque; returns the residual error history of a run in which a
// constant joint-space τ_ext starts at t_on (a sample time).
struct LoopResult {
  double max_error_before = 0.0;  // max |r| before the onset
  double max_law_error = 0.0;  // max |r − (1 − e^{−K (t − t_on)}) τ_ext| after the onset
};

LoopResult run_constant_torque_loop(double gain, const VectorX& tau_ext, double t_on, double t_end,
                                    bool jitter) {
  const Model model = test::paper_arm_model();
  SimulatedArm arm(model);
  Data ctrl(model);
  SineTracker tracker(model.nq());
  // Switched between steps (not at RK stage times), so the onset falls exactly on a sample.
  bool on = false;
  arm.external = [&](const Model&, Data&, double, const VectorX&, const VectorX&, VectorX& out) {
    if (on) out += tau_ext;
  };
  MomentumObserver obs(model, gain);
  Data data(model);
  VectorX tau = tracker.torque(model, ctrl, 0.0, arm.q, arm.dq);
  EXPECT_TRUE(obs.reset(model, data, 0.0, arm.q, arm.dq, tau).ok());
  SeededRng rng(5);
  LoopResult res;
  while (arm.t < t_end) {
    // Non-uniform steps: every step between 0.2 and 2 ms.
    const double h = jitter ? rng.uniform(0.2e-3, 2e-3) : kDt;
    on = arm.t >= t_on - 1e-9;
    const double t_next = (!on && arm.t + h > t_on - 1e-9) ? t_on : arm.t + h;
    arm.step(tau, t_next - arm.t);
    tau = tracker.torque(model, ctrl, arm.t, arm.q, arm.dq);
    EXPECT_TRUE(obs.update(model, data, arm.t, arm.q, arm.dq, tau).ok());
    const VectorX& r = obs.residual();
    if (!on) {
      res.max_error_before = std::max(res.max_error_before, r.cwiseAbs().maxCoeff());
    } else {
      const VectorX law = (1.0 - std::exp(-gain * (arm.t - t_on))) * tau_ext;
      res.max_law_error = std::max(res.max_law_error, (r - law).cwiseAbs().maxCoeff());
    }
  }
  return res;
}

TEST(MomentumObserver, ResidualFollowsTheFirstOrderLawAfterAConstantExternalTorque) {
  const VectorX tau_ext = (VectorX(7) << 3, -2, 1.5, 1, -0.5, 0.4, 0.2).finished();
  for (double gain : {50.0, 100.0, 200.0}) {
    const LoopResult res =
        run_constant_torque_loop(gain, tau_ext, 0.3, 0.3 + 8 / gain + 0.2, false);
    // Exact model: without contact the residual is the integration error only (O(Δt²)).
    EXPECT_LT(res.max_error_before, 1e-4) << "K = " << gain;
    // With contact: r_k = (1 − e^{−K t}) τ_ext up to the trapezoidal error of Cᵀq̇ − g.
    EXPECT_LT(res.max_law_error, 1e-3 * tau_ext.cwiseAbs().maxCoeff()) << "K = " << gain;
  }
}

TEST(MomentumObserver, NonUniformTimeStepsFollowTheSameLaw) {
  const VectorX tau_ext = (VectorX(7) << -2, 2, 1, -1, 0.5, 0.3, -0.2).finished();
  const LoopResult res = run_constant_torque_loop(100.0, tau_ext, 0.25, 0.5, true);
  EXPECT_LT(res.max_error_before, 1e-3);
  EXPECT_LT(res.max_law_error, 5e-3 * tau_ext.cwiseAbs().maxCoeff());
}

TEST(MomentumObserver, PerJointGainsGiveEachJointItsOwnTimeConstant) {
  const Model model = test::paper_arm_model();
  const VectorX gains = (VectorX(7) << 20, 40, 60, 80, 100, 150, 200).finished();
  MomentumObserver obs(model, gains);
  // A robot at rest held by τ = g(q) − τ_ext, i.e. an external torque that the controller
  // balances: q, q̇ stay constant and r must converge to τ_ext joint by joint.
  Data data(model);
  const VectorX q = (VectorX(7) << 0.1, 0.5, -0.3, 1.0, 0.2, -0.4, 0.3).finished();
  const VectorX dq = VectorX::Zero(7);
  const VectorX tau_ext = VectorX::Constant(7, 1.0);
  const VectorX g = gravity_torques(model, data, q);
  const VectorX tau = g - tau_ext;
  ASSERT_TRUE(obs.reset(model, data, 0.0, q, dq, tau).ok());
  double t = 0.0;
  for (int k = 0; k < 100; ++k) {
    t += kDt;
    ASSERT_TRUE(obs.update(model, data, t, q, dq, tau).ok());
  }
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(obs.residual()[i], 1.0 - std::exp(-gains[i] * t), 1e-12) << "joint " << i + 1;
  }
}

TEST(MomentumObserver, NonIncreasingTimeIsRejectedAndChangesNothing) {
  const Model model = test::paper_arm_model();
  MomentumObserver obs(model, 100.0);
  Data data(model);
  const VectorX q = VectorX::Constant(7, 0.2), dq = VectorX::Constant(7, 0.1),
                tau = VectorX::Ones(7);
  ASSERT_TRUE(obs.reset(model, data, 1.0, q, dq, tau).ok());
  ASSERT_TRUE(obs.update(model, data, 1.001, q, dq, tau).ok());
  const VectorX r = obs.residual();
  for (double t : {1.001, 1.0005}) {
    const Status s = obs.update(model, data, t, q, dq, tau);
    EXPECT_EQ(s.code, StatusCode::kNonIncreasingTime);
    EXPECT_EQ(s.channel, Channel::kTime);
  }
  EXPECT_EQ(obs.time(), 1.001);
  EXPECT_TRUE(obs.residual() == r);
}

TEST(MomentumObserver, UpdateBeforeResetReportsNotInitialized) {
  const Model model = test::paper_arm_model();
  Data data(model);
  MomentumObserver obs(model, 100.0);
  const VectorX z = VectorX::Zero(7);
  EXPECT_EQ(obs.update(model, data, 0.1, z, z, z).code, StatusCode::kNotInitialized);
}

// A workspace or model of another size (a review's 3-joint Data with the 7-joint arm): reset and
// update returned ok and the momentum pass wrote past the workspace's arrays.
TEST(MomentumObserver, AWorkspaceOrModelOfAnotherSizeIsWrongSize) {
  const Model model = test::paper_arm_model();
  const Model small = random_chain({.n = 3});
  Data data(model), small_data(small);
  MomentumObserver obs(model, 100.0);
  const VectorX z = VectorX::Zero(7);
  EXPECT_EQ(obs.reset(model, small_data, 0.0, z, z, z).code, StatusCode::kWrongSize);
  EXPECT_EQ(obs.reset(small, small_data, 0.0, z, z, z).code, StatusCode::kWrongSize);
  ASSERT_TRUE(obs.reset(model, data, 0.0, z, z, z).ok());
  EXPECT_EQ(obs.update(model, small_data, 0.001, z, z, z).code, StatusCode::kWrongSize);
  EXPECT_EQ(obs.update(small, data, 0.001, z, z, z).code, StatusCode::kWrongSize);
  EXPECT_TRUE(obs.update(model, data, 0.001, z, z, z).ok());
}

TEST(MomentumObserver, BadInputsNameTheChannelAndIndexAndLeaveTheStateBitIdentical) {
  const Model model = test::paper_arm_model();
  SeededRng rng(3);
  std::vector<VectorX> qs, dqs, taus;
  for (int k = 0; k < 50; ++k) {
    qs.push_back(rng.uniform_vector(7, -2, 2));
    dqs.push_back(rng.uniform_vector(7, -1, 1));
    taus.push_back(rng.uniform_vector(7, -10, 10));
  }
  MomentumObserver clean(model, 80.0), dirty(model, 80.0);
  Data data(model);  // scratch: shared by both observers
  ASSERT_TRUE(clean.reset(model, data, 0.0, qs[0], dqs[0], taus[0]).ok());
  ASSERT_TRUE(dirty.reset(model, data, 0.0, qs[0], dqs[0], taus[0]).ok());
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 1; k < 50; ++k) {
    const double t = k * kDt;
    if (k % 5 == 0) {
      // A bad sample of each kind before the good one.
      VectorX bad = qs[k];
      bad[k % 7] = nan;
      Status s = dirty.update(model, data, t, bad, dqs[k], taus[k]);
      EXPECT_EQ(s.code, StatusCode::kNonFinite);
      EXPECT_EQ(s.channel, Channel::kPosition);
      EXPECT_EQ(s.index, k % 7);
      bad = dqs[k];
      bad[(k + 1) % 7] = inf;
      s = dirty.update(model, data, t, qs[k], bad, taus[k]);
      EXPECT_EQ(s.channel, Channel::kVelocity);
      EXPECT_EQ(s.index, (k + 1) % 7);
      bad = taus[k];
      bad[(k + 2) % 7] = -inf;
      s = dirty.update(model, data, t, qs[k], dqs[k], bad);
      EXPECT_EQ(s.channel, Channel::kTorque);
      EXPECT_EQ(s.index, (k + 2) % 7);
      s = dirty.update(model, data, t, qs[k].head(6), dqs[k], taus[k]);
      EXPECT_EQ(s.code, StatusCode::kWrongSize);
      EXPECT_EQ(s.channel, Channel::kPosition);
      s = dirty.update(model, data, nan, qs[k], dqs[k], taus[k]);
      EXPECT_EQ(s.code, StatusCode::kNonFinite);
      EXPECT_EQ(s.channel, Channel::kTime);
    }
    ASSERT_TRUE(clean.update(model, data, t, qs[k], dqs[k], taus[k]).ok());
    ASSERT_TRUE(dirty.update(model, data, t, qs[k], dqs[k], taus[k]).ok());
    // Bit-identical, not merely close.
    ASSERT_TRUE(clean.residual() == dirty.residual()) << "sample " << k;
  }
}

TEST(MomentumObserver, KnownViscousAndCoulombFrictionIsNotMistakenForContact) {
  Model model = test::paper_arm_model();
  SimulatedArm arm(model);
  arm.friction_viscous = VectorX::Constant(7, 0.5);
  Data ctrl(model);
  SineTracker tracker(7);
  JointFriction friction = JointFriction::none(7);
  friction.viscous = arm.friction_viscous;
  MomentumObserver with(model, 100.0), without(model, 100.0);
  Data data(model);
  with.set_friction(friction);
  VectorX tau = tracker.torque(model, ctrl, 0, arm.q, arm.dq);
  ASSERT_TRUE(with.reset(model, data, 0, arm.q, arm.dq, tau).ok());
  ASSERT_TRUE(without.reset(model, data, 0, arm.q, arm.dq, tau).ok());
  double max_with = 0, max_without_error = 0;
  for (int k = 0; k < 1000; ++k) {
    arm.step(tau, kDt);
    tau = tracker.torque(model, ctrl, arm.t, arm.q, arm.dq);
    ASSERT_TRUE(with.update(model, data, arm.t, arm.q, arm.dq, tau).ok());
    ASSERT_TRUE(without.update(model, data, arm.t, arm.q, arm.dq, tau).ok());
    if (arm.t > 0.1) {
      max_with = std::max(max_with, with.residual().cwiseAbs().maxCoeff());
      // Without the model, r tracks −τ_f (lagged by 1/K).
      const VectorX expected = -friction.viscous.cwiseProduct(arm.dq);
      max_without_error =
          std::max(max_without_error, (without.residual() - expected).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LT(max_with, 1e-4);
  EXPECT_LT(max_without_error, 0.05);
  EXPECT_GT(arm.dq.cwiseAbs().maxCoeff(), 0.05);  // the arm did move
}

TEST(MomentumObserver, CoulombFrictionIsSmoothedLinearlyAroundZeroVelocity) {
  JointFriction f = JointFriction::none(3);
  f.coulomb = VectorX::Constant(3, 2.0);
  f.viscous = VectorX::Constant(3, 0.1);
  f.smoothing_velocity = 0.01;
  VectorX out(3);
  friction_torque(f, Eigen::Vector3d(0.005, -1.0, 0.0), out);
  EXPECT_DOUBLE_EQ(out[0], 0.1 * 0.005 + 2.0 * 0.5);
  EXPECT_DOUBLE_EQ(out[1], -0.1 - 2.0);
  EXPECT_DOUBLE_EQ(out[2], 0.0);
}

TEST(MomentumObserver, PayloadSetAtRunTimeMatchesTheLoadedRobotWithoutAJumpOrAllocation) {
  const Model nominal = test::paper_arm_model();
  Inertia payload;
  payload.mass = 1.5;
  payload.com = Vector3(0.01, -0.02, 0.12);
  payload.inertia_com = Vector3(0.004, 0.005, 0.003).asDiagonal();
  Model loaded = nominal;
  loaded.bodies[7].inertia = loaded.bodies[7].inertia + payload;
  SimulatedArm arm(loaded);
  Data ctrl(loaded);
  SineTracker tracker(7);
  // The caller owns the model the observer runs on: the payload is an edit of it + reanchor.
  Model model = nominal;
  Data data(model);
  MomentumObserver obs(model, 100.0);
  VectorX tau = tracker.torque(loaded, ctrl, 0, arm.q, arm.dq);
  ASSERT_TRUE(obs.reset(model, data, 0, arm.q, arm.dq, tau).ok());
  double r_before = 0, max_after = 0;
  for (int k = 0; k < 800; ++k) {
    if (k == 400) {
      r_before = obs.residual().norm();
      test::AllocationCounter counter;
      model.bodies[7].inertia = nominal.bodies[7].inertia + payload;
      obs.reanchor(model, data);
      if (test::allocation_counting_available()) {
        EXPECT_EQ(counter.count(), 0u);
      }
      // Continuity: the payload change itself does not move r.
      EXPECT_EQ(obs.residual().norm(), r_before);
    }
    arm.step(tau, kDt);
    tau = tracker.torque(loaded, ctrl, arm.t, arm.q, arm.dq);
    ASSERT_TRUE(obs.update(model, data, arm.t, arm.q, arm.dq, tau).ok());
    if (k >= 400 + 8 * 10) max_after = std::max(max_after, obs.residual().cwiseAbs().maxCoeff());
  }
  // Before: the unmodelled payload shows as an external torque (its weight, ~1.5 kg · g).
  EXPECT_GT(r_before, 0.3);
  // After: the model matches the robot; the old error decays with e^{−K t} (8/K s → < 0.04 %).
  EXPECT_LT(max_after, 2e-3 * r_before);
}

// δI in the observer's momentum is the same residual as the model's armature (which the
// dynamics add inside momentum_terms, docs/model.md "Armature"): an arm with rotors on joints 2
// and 5 observed on the model without them, corrected by δI, matches the observer that has them,
// also when δI is set mid-run (no jump), and an observer on the rotor model with δI = −I_a
// (Model::joints[0] is the base's: joint i is joints[i], δI's entry i − 1)
// matches the one without rotors (a negative correction).
TEST(MomentumObserver, InertiaCorrectionActsAsTheArmatureAlongTheJoints) {
  const Model bare = test::paper_arm_model();
  Model rotors = bare;
  rotors.joints[1].armature = 0.4;
  rotors.joints[4].armature = 0.15;
  VectorX armature = VectorX::Zero(7);
  armature[0] = 0.4;
  armature[3] = 0.15;
  SimulatedArm arm(rotors);
  Data ctrl(rotors);
  SineTracker tracker(7);
  MomentumObserver on_rotors(rotors, 80.0), corrected(bare, 80.0), late(bare, 80.0),
      plain(bare, 80.0), negative(rotors, 80.0);
  corrected.set_inertia_correction(armature);
  negative.set_inertia_correction(-armature);
  Data d_rotors(rotors), d_bare(bare);
  VectorX tau = tracker.torque(rotors, ctrl, 0, arm.q, arm.dq);
  for (MomentumObserver* o : {&corrected, &late, &plain})
    ASSERT_TRUE(o->reset(bare, d_bare, 0, arm.q, arm.dq, tau).ok());
  for (MomentumObserver* o : {&on_rotors, &negative})
    ASSERT_TRUE(o->reset(rotors, d_rotors, 0, arm.q, arm.dq, tau).ok());
  double worst = 0, worst_late = 0, worst_negative = 0, plain_peak = 0;
  for (int k = 0; k < 1500; ++k) {
    if (k == 500) late.set_inertia_correction(armature);
    arm.step(tau, kDt);
    tau = tracker.torque(rotors, ctrl, arm.t, arm.q, arm.dq);
    for (MomentumObserver* o : {&corrected, &late, &plain})
      ASSERT_TRUE(o->update(bare, d_bare, arm.t, arm.q, arm.dq, tau).ok());
    for (MomentumObserver* o : {&on_rotors, &negative})
      ASSERT_TRUE(o->update(rotors, d_rotors, arm.t, arm.q, arm.dq, tau).ok());
    const double scale = std::max(1.0, on_rotors.residual().cwiseAbs().maxCoeff());
    worst = std::max(worst,
                     (corrected.residual() - on_rotors.residual()).cwiseAbs().maxCoeff() / scale);
    worst_negative = std::max(
        worst_negative, (negative.residual() - plain.residual()).cwiseAbs().maxCoeff() / scale);
    plain_peak =
        std::max(plain_peak, (plain.residual() - on_rotors.residual()).cwiseAbs().maxCoeff());
    if (k >= 500 + 8 * 12)  // 8 time constants after the change: its past has decayed
      worst_late = std::max(worst_late,
                            (late.residual() - on_rotors.residual()).cwiseAbs().maxCoeff() / scale);
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_LT(worst_negative, 1e-12);
  EXPECT_LT(worst_late, 1e-3);
  EXPECT_GT(plain_peak, 0.05);  // without δI the rotors show as an external torque
  EXPECT_THROW(plain.set_inertia_correction(VectorX::Ones(3)), Error);
  EXPECT_THROW(plain.set_inertia_correction(VectorX::Constant(7, std::nan(""))), Error);
}

TEST(MomentumObserver, RejectsNonPositiveOrWrongSizedGains) {
  const Model model = test::paper_arm_model();
  EXPECT_THROW(MomentumObserver(model, 0.0), Error);
  EXPECT_THROW(MomentumObserver(model, -5.0), Error);
  EXPECT_THROW(MomentumObserver(model, VectorX::Ones(3)), Error);
  EXPECT_NO_THROW(MomentumObserver(model, VectorX::Constant(7, 10.0)));
}

TEST(MomentumObserver, UpdatesAllocateNothing) {
  if (!test::allocation_counting_available()) GTEST_SKIP() << "sanitizer build";
  const Model model = test::paper_arm_model();
  MomentumObserver obs(model, 100.0);
  Data data(model);
  SeededRng rng(9);
  const VectorX q = rng.uniform_vector(7, -2, 2), dq = rng.uniform_vector(7, -1, 1),
                tau = rng.uniform_vector(7, -5, 5);
  ASSERT_TRUE(obs.reset(model, data, 0, q, dq, tau).ok());
  test::AllocationCounter counter;
  double t = 0;
  int failures = 0;
  for (int k = 0; k < 10000; ++k) {
    t += (k % 3 == 0) ? 1e-3 : 0.9e-3;  // varying Δt exercises the exponential cache too
    failures += obs.update(model, data, t, q, dq, tau).ok() ? 0 : 1;
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_EQ(failures, 0);
}

}  // namespace
}  // namespace extwrench
