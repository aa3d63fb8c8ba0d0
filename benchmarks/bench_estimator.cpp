// Per-sample estimator updates, ours against KDL's ChainExternalWrenchEstimator, replaying the
// same trajectory (robots.hpp: smooth motion at 1 kHz, a constant force on link 6) on both sides.
#include <benchmark/benchmark.h>

#include <kdl/chainexternalwrenchestimator.hpp>

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

// The momentum residual (4) alone: O(n) momentum terms + the exact first-order update.
void BM_Residual_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const Trajectory& tr = flange_trajectory();
  MomentumObserver observer(arm.model, kGain);
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
BENCHMARK(BM_Residual_Ours);

}  // namespace
}  // namespace extwrench::bench
