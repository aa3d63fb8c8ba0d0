// Per-sample estimator updates, ours against KDL's ChainExternalWrenchEstimator, replaying the
// same trajectory (robots.hpp: smooth motion at 1 kHz, a constant force on link 6) on both sides.
#include <benchmark/benchmark.h>

#include <kdl/chainexternalwrenchestimator.hpp>
#include <optional>

#include "extwrench/observer/momentum_observer.hpp"
#include "robots.hpp"

namespace extwrench::bench {
namespace {

constexpr double kGain = 100.0;  ///< K [1/s], on every joint, on both sides

/// Sample k of the replay (k grows without bound; the trajectory is periodic).
std::size_t sample(std::size_t k) { return k % Trajectory::kNumSamples; }
/// t_k = k dt, as a fixed-rate control loop computes it.
double stamp(std::size_t k, const Trajectory& tr) { return static_cast<double>(k) * tr.dt; }

// KDL 1.5.1: momentum observer (B from ChainDynParam, Ḃ by differencing B, C q̇, g), then the
// end-effector Jacobian, re-referenced to the flange, and an SVD pseudo-inverse of Jᵀ. Same K,
// same sample time, its low-pass filter off (we have none).
void BM_ExtWrench_Kdl(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const Trajectory& tr = flange_trajectory();
  const KDL::Vector g(arm.model.gravity.x(), arm.model.gravity.y(), arm.model.gravity.z());
  KDL::ChainExternalWrenchEstimator estimator(arm.chain, g, 1.0 / tr.dt, kGain, 0.0);
  if (estimator.setInitialMomentum(tr.kq[0], tr.kdq[0]) != 0) {
    state.SkipWithError("KDL setInitialMomentum failed");
    return;
  }
  KDL::Wrench wrench;
  std::size_t k = 1;
  auto call = [&](std::size_t) {
    const std::size_t s = sample(k++);
    benchmark::DoNotOptimize(estimator.JntToExtWrench(tr.kq[s], tr.kdq[s], tr.ktau[s], wrench));
    benchmark::DoNotOptimize(wrench.force.data);
  };
  for (auto _ : state) call(0);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_ExtWrench_Kdl);

// The momentum residual (4) alone: O(n) momentum terms + the exact first-order update; with a
// calibrated friction (`friction`: tanh, or the Dahl sign and its state, advanced every sample)
// on every joint. The observer has no branch on the residual: the same path with any friction.
void residual_update(benchmark::State& state, const std::optional<JointFriction>& friction) {
  const PaperArm& arm = paper_arm();
  const Trajectory& tr = flange_trajectory();
  MomentumObserver observer(arm.model, kGain);
  if (friction) observer.set_friction(*friction);
  Data data(arm.model);
  if (!observer.reset(arm.model, data, 0.0, tr.q[0], tr.dq[0], tr.tau[0]).ok()) {
    state.SkipWithError("reset failed");
    return;
  }
  std::size_t k = 1;
  auto call = [&](std::size_t) {
    const std::size_t s = sample(k);
    const Status st = observer.update(arm.model, data, stamp(k, tr), tr.q[s], tr.dq[s], tr.tau[s]);
    benchmark::DoNotOptimize(st);
    ++k;
  };
  for (auto _ : state) call(0);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}

JointFriction calibrated_friction(int n, SmoothSign sign) {
  JointFriction f = JointFriction::none(n);
  f.sign = sign;
  f.viscous = VectorX::Constant(n, 0.01);
  f.coulomb = VectorX::Constant(n, 0.3);
  f.offset = VectorX::Constant(n, 0.01);
  if (sign == SmoothSign::kDahl) {
    f.presliding = VectorX::Constant(n, 0.005);
  } else {
    f.joint_smoothing = VectorX::Constant(n, 0.05);
  }
  return f;
}

void BM_Residual_Ours(benchmark::State& state) { residual_update(state, std::nullopt); }
BENCHMARK(BM_Residual_Ours);
void BM_Residual_Ours_TanhFriction(benchmark::State& state) {
  residual_update(state, calibrated_friction(paper_arm().model.nq(), SmoothSign::kTanh));
}
BENCHMARK(BM_Residual_Ours_TanhFriction);
void BM_Residual_Ours_DahlFriction(benchmark::State& state) {
  residual_update(state, calibrated_friction(paper_arm().model.nq(), SmoothSign::kDahl));
}
BENCHMARK(BM_Residual_Ours_DahlFriction);

}  // namespace
}  // namespace extwrench::bench
