// The residual filter (observer/residual_filter.hpp) against the continuous-time response of
// two critically damped first-order sections, ω²/(s + ω)²: a held step, a sine's gain, and the
// estimator's residual passing through it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/observer/residual_filter.hpp"
#include "support/alloc_counter.hpp"
#include "support/random.hpp"
#include "support/test_robots.hpp"

namespace extwrench {
namespace {

constexpr double kCutoff = 20.0;  // [Hz]
const double kOmega = 2.0 * std::numbers::pi * kCutoff;

// Largest error against 1 − (1 + ωt) e^{−ωt} of a unit step held from t = 0, over 0.2 s.
double step_error(double dt) {
  ResidualFilter filter(VectorX::Constant(1, kCutoff), 1);
  double worst = 0.0;
  for (int k = 1; k * dt <= 0.2; ++k) {
    VectorX x = VectorX::Ones(1);
    filter.apply(dt, x);
    const double t = k * dt;
    worst = std::max(worst, std::abs(x[0] - (1.0 - (1.0 + kOmega * t) * std::exp(-kOmega * t))));
  }
  return worst;
}

TEST(ResidualFilter, AHeldStepFollowsTheCriticallyDampedResponseToFirstOrderInTheStep) {
  const double coarse = step_error(1e-3), fine = step_error(0.5e-3);
  EXPECT_LT(coarse, 0.03);               // 1 kHz: within 3 % of the step
  EXPECT_NEAR(coarse / fine, 2.0, 0.2);  // the error halves with the step
}

TEST(ResidualFilter, ASineAtFiveTimesTheCutoffPassesAtTheAnalyticGain) {
  // |H(jΩ)| = 1 / (1 + (Ω/ω)²) = 1/26 at Ω = 5ω.
  const double f = 5.0 * kCutoff, dt = 1e-5;
  ResidualFilter filter(VectorX::Constant(1, kCutoff), 1);
  double c = 0.0, s = 0.0;
  const int periods_settle = 20, periods_measure = 20;
  const int per_period = static_cast<int>(std::lround(1.0 / (f * dt)));
  for (int k = 1; k <= (periods_settle + periods_measure) * per_period; ++k) {
    const double phase = 2.0 * std::numbers::pi * f * k * dt;
    VectorX x = VectorX::Constant(1, std::sin(phase));
    filter.apply(dt, x);
    if (k > periods_settle * per_period) {
      c += x[0] * std::cos(phase);
      s += x[0] * std::sin(phase);
    }
  }
  const double amplitude = 2.0 * std::hypot(c, s) / (periods_measure * per_period);
  EXPECT_NEAR(amplitude, 1.0 / 26.0, 0.02 / 26.0);
}

TEST(ResidualFilter, UnfilteredChannelsAndConstantsPassBitForBitWithoutAllocation) {
  ResidualFilter filter(VectorX{{kCutoff, 0.0, kCutoff}}, 3);
  ASSERT_TRUE(filter.enabled());
  filter.reset(VectorX{{0.7, 0.0, 0.0}});
  test::SeededRng rng(4);
  test::AllocationCounter counter;
  for (int k = 0; k < 1000; ++k) {
    const double dt = rng.uniform(0.2e-3, 2e-3);  // changing steps recompute the weights
    const double raw = rng.uniform(-5, 5);
    VectorX x{{0.7, raw, 0.0}};
    filter.apply(dt, x);
    ASSERT_EQ(x[0], 0.7);  // at rest on a constant: unchanged to the bit
    ASSERT_EQ(x[1], raw);  // cutoff 0: passes
    ASSERT_EQ(x[2], 0.0);
  }
  if (test::allocation_counting_available()) {
    VectorX x = VectorX::Ones(3);  // (allocated before counting)
    test::AllocationCounter inner;
    filter.apply(1e-3, x);
    EXPECT_EQ(inner.count(), 0u);
  }
  EXPECT_FALSE(ResidualFilter(VectorX::Zero(1), 3).enabled());
}

// The estimator's τ̂_ext is the observer's residual through the filter: the same samples with and
// without observer.residual_cutoff, the second's residual filtered here.
TEST(ResidualFilter, TheEstimatorsResidualIsTheObserversThroughTheFilter) {
  const Model model = test::paper_arm_model();
  EstimatorOptions plain;
  plain.observer_gain = VectorX::Constant(1, 50.0);
  EstimatorOptions filtered = plain;
  filtered.residual_cutoff = VectorX{{kCutoff, kCutoff, kCutoff, kCutoff, 0.0, 0.0, 0.0}};
  ContactEstimator a(model, {}, filtered), b(model, {}, plain);
  test::SeededRng rng(11);
  VectorX q = rng.uniform_vector(7, -1, 1);
  const VectorX dq = rng.uniform_vector(7, -0.5, 0.5);
  VectorX tau = rng.uniform_vector(7, -5, 5);
  ASSERT_TRUE(a.reset(0.0, q, dq, tau).ok());
  ASSERT_TRUE(b.reset(0.0, q, dq, tau).ok());
  ResidualFilter reference(filtered.residual_cutoff, 7);
  double t = 0.0;
  for (int k = 0; k < 500; ++k) {
    const double t_prev = t;
    t += k % 2 ? 1e-3 : 1.2e-3;
    const double dt = t - t_prev;  // the step as the estimator takes it from the time stamps
    q += dt * dq;
    tau += rng.uniform_vector(7, -0.5, 0.5);  // noise the model does not explain: a residual
    ASSERT_TRUE(a.update(t, q, dq, tau).ok());
    ASSERT_TRUE(b.update(t, q, dq, tau).ok());
    VectorX expected = b.result().residual;
    reference.apply(dt, expected);
    ASSERT_EQ(a.result().residual, expected) << "sample " << k;
  }
}

// observer.velocity_cutoff: the estimator's momentum takes q̇ through the same filter, started at
// rest on the first q̇ — without friction (which takes the measured q̇), bit for bit an estimator
// without the filter fed the filtered q̇.
TEST(VelocityFilter, TheMomentumTakesTheFilteredVelocity) {
  const Model model = test::paper_arm_model();
  EstimatorOptions plain;
  plain.observer_gain = VectorX::Constant(1, 50.0);
  plain.friction = JointFriction::none(7);
  EstimatorOptions filtered = plain;
  filtered.velocity_cutoff = VectorX{{kCutoff, kCutoff, kCutoff, kCutoff, 0.0, 0.0, 0.0}};
  ContactEstimator a(model, {}, filtered), b(model, {}, plain);
  test::SeededRng rng(13);
  VectorX q = rng.uniform_vector(7, -1, 1);
  VectorX dq = rng.uniform_vector(7, -0.5, 0.5);
  const VectorX tau = rng.uniform_vector(7, -5, 5);
  ASSERT_TRUE(a.reset(0.0, q, dq, tau).ok());
  ASSERT_TRUE(b.reset(0.0, q, dq, tau).ok());
  ResidualFilter reference(filtered.velocity_cutoff, 7);
  reference.reset(dq);
  double t = 0.0;
  for (int k = 0; k < 500; ++k) {
    const double t_prev = t;
    t += k % 2 ? 1e-3 : 1.2e-3;
    q += (t - t_prev) * dq;
    dq += rng.uniform_vector(7, -0.05, 0.05);  // a noisy velocity
    VectorX dq_filtered = dq;
    reference.apply(t - t_prev, dq_filtered);
    ASSERT_TRUE(a.update(t, q, dq, tau).ok());
    ASSERT_TRUE(b.update(t, q, dq_filtered, tau).ok());
    ASSERT_EQ(a.result().residual, b.result().residual) << "sample " << k;
  }
  // A bad sample is refused before the filter: the state goes on as if it had not come.
  VectorX bad = dq;
  bad[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(a.update(t + 1e-3, q, bad, tau).ok());
  VectorX dq_filtered = dq;
  reference.apply((t + 2e-3) - t, dq_filtered);  // the step as the estimator takes it
  ASSERT_TRUE(a.update(t + 2e-3, q, dq, tau).ok());
  ASSERT_TRUE(b.update(t + 2e-3, q, dq_filtered, tau).ok());
  EXPECT_EQ(a.result().residual, b.result().residual);
}

}  // namespace
}  // namespace extwrench
