// The full per-sample update of ContactEstimator (residual + q̈̂ + no-contact base RNEA + detection
// and isolation + the Table I case + the point on the link's geometry), for every configuration
// of Table I, and the like-for-like comparison with KDL's JntToExtWrench (case E, l = n).
// Each estimator first runs kWarmup samples so that the contact is declared and every sample
// timed takes the full path; the counters "contact", "link" and "surface" say that it did.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <kdl/chainexternalwrenchestimator.hpp>
#include <optional>
#include <string>
#include <vector>

#include "extwrench/core/denormals.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/estimation/damped_least_squares.hpp"
#include "extwrench/observer/momentum_observer.hpp"
#include "robots.hpp"

namespace extwrench::bench {
namespace {

constexpr double kGain = 100.0;       ///< K [1/s] on every joint (KDL's estimation_gain too)
constexpr std::size_t kWarmup = 500;  ///< samples before timing: past detection's min_duration
constexpr std::size_t kLatencyCalls = 1'000'000;
constexpr std::size_t kKdlLatencyCalls = 200'000;

std::size_t sample(std::size_t k) { return k % Trajectory::kNumSamples; }
double stamp(std::size_t k, const Trajectory& tr) { return static_cast<double>(k) * tr.dt; }

struct Config {
  SensorType sensor;
  ContactModel contact;
  const char* name;
};
constexpr Config kTableI[] = {
    {SensorType::kForceTorque, ContactModel::kPureForce, "ft/pure_force"},
    {SensorType::kForceTorque, ContactModel::kKnownPoint, "ft/known_point"},
    {SensorType::kForce, ContactModel::kPureForce, "force/pure_force"},
    {SensorType::kForce, ContactModel::kKnownPoint, "force/known_point"},
    {SensorType::kNone, ContactModel::kPureForce, "none/pure_force"},
    {SensorType::kNone, ContactModel::kKnownPoint, "none/known_point"},
};

EstimatorOptions options_for(const Config& c, const Trajectory& tr) {
  EstimatorOptions o;
  o.sensor.type = c.sensor;
  o.sensor.X_WS = tr.X_WS;
  o.contact.model = c.contact;
  if (c.contact == ContactModel::kKnownPoint) {
    o.contact.link = tr.contact.body;
    o.contact.point_L = tr.contact.point_B;
  }
  o.observer_gain = VectorX::Constant(1, kGain);
  return o;
}

/// Replays `tr` through one estimator; call(k) runs sample k (k increases: t_k = k dt).
class Replay {
 public:
  Replay(const Model& model, const GeometryModel& geometry, const EstimatorOptions& options,
         const Trajectory& tr)
      : estimator_(model, geometry, options),
        tr_(tr),
        with_sensor_(options.sensor.type != SensorType::kNone) {
    ok_ = estimator_.reset(0.0, tr.q[0], tr.dq[0], tr.tau[0]).ok();
    while (k_ < kWarmup) step();
  }
  bool ok() const { return ok_; }
  Status step() {
    const std::size_t s = sample(k_);
    const double t = stamp(k_, tr_);
    ++k_;
    return with_sensor_ ? estimator_.update(t, tr_.q[s], tr_.dq[s], tr_.tau[s], tr_.ft_S[s])
                        : estimator_.update(t, tr_.q[s], tr_.dq[s], tr_.tau[s]);
  }
  const ContactEstimator& estimator() const { return estimator_; }

 private:
  ContactEstimator estimator_;
  const Trajectory& tr_;
  bool with_sensor_;
  bool ok_ = false;
  std::size_t k_ = 1;
};

void report(benchmark::State& state, const Replay& replay, double allocs) {
  const ContactEstimate& e = replay.estimator().result();
  state.counters["allocs"] = allocs;
  state.counters["contact"] = e.contact ? 1.0 : 0.0;
  state.counters["link"] = e.link;
  state.counters["surface"] = e.has(EstimateFlag::kSurfacePoint) ? 1.0 : 0.0;
  state.SetLabel(describe_flags(e.flags));
}

void run_update(benchmark::State& state, const Model& model, const GeometryModel& geometry,
                const EstimatorOptions& options, const Trajectory& tr) {
  Replay replay(model, geometry, options, tr);
  if (!replay.ok()) {
    state.SkipWithError("estimator reset failed");
    return;
  }
  for (auto _ : state) {
    const Status st = replay.step();
    benchmark::DoNotOptimize(st);
  }
  const double allocs = allocations_per_call([&](int) { (void)replay.step(); });
  report(state, replay, allocs);
}

// Like for like with KDL's JntToExtWrench: the residual and the wrench at the flange origin from
// the joint torques alone (case E, l = n, known point = link 7's origin), detection included.
void BM_ResidualEeWrench_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const Trajectory& tr = flange_trajectory();
  const Config c{SensorType::kNone, ContactModel::kKnownPoint, "none/known_point"};
  run_update(state, arm.model, arm.geometry, options_for(c, tr), tr);
}
BENCHMARK(BM_ResidualEeWrench_Ours);

// Latency of single calls measured with the steady clock over many calls: min, median, p99,
// p99.9, max [ns]. The clock's own cost (a back-to-back pair of now()) is reported as clock_ns
// and is included in every figure.
template <class Step>
void measure_latency(benchmark::State& state, std::size_t calls, Step&& step) {
  using Clock = std::chrono::steady_clock;
  std::vector<std::int64_t> ns(calls);
  for (auto _ : state) {
    for (std::size_t i = 0; i < calls; ++i) {
      const auto t0 = Clock::now();
      step();
      const auto t1 = Clock::now();
      ns[i] = std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
    }
  }
  std::vector<std::int64_t> clock(10000);
  for (auto& c : clock) {
    const auto t0 = Clock::now();
    const auto t1 = Clock::now();
    c = std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
  }
  std::sort(ns.begin(), ns.end());
  std::nth_element(clock.begin(), clock.begin() + clock.size() / 2, clock.end());
  auto at = [&](double p) {
    return static_cast<double>(
        ns[std::min(ns.size() - 1, static_cast<std::size_t>(p * static_cast<double>(ns.size())))]);
  };
  state.counters["calls"] = static_cast<double>(calls);
  state.counters["min_ns"] = static_cast<double>(ns.front());
  state.counters["p50_ns"] = at(0.5);
  state.counters["p99_ns"] = at(0.99);
  state.counters["p999_ns"] = at(0.999);
  state.counters["max_ns"] = static_cast<double>(ns.back());
  state.counters["clock_ns"] = static_cast<double>(clock[clock.size() / 2]);
}

// Subnormal numbers (issue 15, jitter): the F/T update on the link-6 trajectory with every joint
// velocity replaced by `speed` (0, a subnormal 1e-310, or 1e-300, whose products underflow),
// without and with ScopedFlushDenormals around the loop. Timing only: such velocities are not
// the trajectory's, and the estimate is not meant to be right.
void BM_FullUpdate_TinyVelocity(benchmark::State& state, double speed, bool flush) {
  const PaperArm& arm = paper_arm();
  const Trajectory& tr = link6_trajectory();
  ContactEstimator estimator(arm.model, arm.geometry, options_for(kTableI[0], tr));
  const VectorX dq = VectorX::Constant(arm.model.nq(), speed);
  if (!estimator.reset(0.0, tr.q[0], dq, tr.tau[0]).ok()) {
    state.SkipWithError("estimator reset failed");
    return;
  }
  std::optional<ScopedFlushDenormals> guard;
  if (flush) guard.emplace();
  std::size_t k = 1;
  for (auto _ : state) {
    const std::size_t s = sample(k);
    const Status st = estimator.update(stamp(k, tr), tr.q[s], dq, tr.tau[s], tr.ft_S[s]);
    benchmark::DoNotOptimize(st);
    ++k;
  }
  state.counters["contact"] = estimator.result().contact ? 1.0 : 0.0;
}
BENCHMARK_CAPTURE(BM_FullUpdate_TinyVelocity, zero, 0.0, false);
BENCHMARK_CAPTURE(BM_FullUpdate_TinyVelocity, subnormal, 1e-310, false);
BENCHMARK_CAPTURE(BM_FullUpdate_TinyVelocity, underflowing, 1e-300, false);
BENCHMARK_CAPTURE(BM_FullUpdate_TinyVelocity, subnormal_flushed, 1e-310, true);
BENCHMARK_CAPTURE(BM_FullUpdate_TinyVelocity, underflowing_flushed, 1e-300, true);

// Where the full update's time goes (issue 15): its first stages, cumulatively, with the public
// functions ContactEstimator::update calls, on the samples of BM_FullUpdate_Ours/ft/pure_force/
// capsules (the link-6 trajectory, K = 100). 1: the fused momentum + bias pass (poses, B q̇,
// Cᵀq̇, g, the world-frame inertias, c(q, q̇)); 2: + the input checks and the observer's
// integration; 3: + q̈̂ = B⁻¹ (τ − τ_f + r − c) (CRBA, LDLᵀ). The full update's median minus
// stage 3's is stages 4–10: ground wrench, sensor, release, detection, isolation, the Table I
// case, the point, the uncertainty.
void BM_UpdateStages_Ours(benchmark::State& state, int last_stage) {
  const PaperArm& arm = paper_arm();
  const Model& model = arm.model;
  const Trajectory& tr = link6_trajectory();
  Data data(model);
  MomentumObserver observer(model, kGain);
  if (!observer.reset(model, data, 0.0, tr.q[0], tr.dq[0], tr.tau[0]).ok()) {
    state.SkipWithError("observer reset failed");
    return;
  }
  const int n = model.nq();
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 12> mass_ldlt(n, n);
  VectorX ddq = VectorX::Zero(n);
  std::size_t k = 1;
  auto step = [&] {
    const std::size_t s = sample(k);
    const double t = stamp(k, tr);
    ++k;
    if (last_stage >= 2) {
      const Status st = observer.validate(t, tr.q[s], tr.dq[s], tr.tau[s]);
      benchmark::DoNotOptimize(st);
    }
    momentum_and_bias_terms(model, data, tr.q[s], tr.dq[s]);
    if (last_stage >= 2) observer.integrate(data, t, tr.q[s], tr.dq[s], tr.tau[s], tr.dq[s]);
    if (last_stage >= 3) {
      crba_no_kinematics(model, data);
      ddq = tr.tau[s] - observer.friction_torque() + observer.residual() - data.tau;
      mass_ldlt = data.M;
      if (ldlt_in_place(mass_ldlt)) ldlt_solve(mass_ldlt, ddq);
      benchmark::DoNotOptimize(ddq.data());
    }
    benchmark::DoNotOptimize(data.tau.data());
    benchmark::ClobberMemory();
  };
  for (auto _ : state) step();
  state.counters["allocs"] = allocations_per_call([&](int) { step(); });
}
BENCHMARK_CAPTURE(BM_UpdateStages_Ours, 1_momentum_and_bias, 1);
BENCHMARK_CAPTURE(BM_UpdateStages_Ours, 2_observer, 2);
BENCHMARK_CAPTURE(BM_UpdateStages_Ours, 3_acceleration, 3);

/// Minor and major page faults of the calling thread so far.
long thread_page_faults() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt + usage.ru_majflt;
}

// The first updates of a new estimator (issue 15, jitter): the first sample, the first sample in
// contact (the first geometric isolation: lines against the collision shapes) and the worst of
// the first kFirstCalls, each with the page faults of the thread during it. One estimator per
// process run (Iterations(1)): later ones would find the process already warm. Run it several
// times in fresh processes.
void first_updates(benchmark::State& state, const Model& model, const GeometryModel& geometry,
                   const EstimatorOptions& options, const Trajectory& tr) {
  using Clock = std::chrono::steady_clock;
  constexpr std::size_t kFirstCalls = 2000;
  std::vector<std::int64_t> ns(kFirstCalls);
  std::vector<long> faults(kFirstCalls);
  std::size_t first_contact = kFirstCalls;
  for (auto _ : state) {
    state.PauseTiming();
    ContactEstimator estimator(model, geometry, options);
    const bool with_sensor = options.sensor.type != SensorType::kNone;
    if (!estimator.reset(0.0, tr.q[0], tr.dq[0], tr.tau[0]).ok()) {
      state.SkipWithError("estimator reset failed");
      return;
    }
    state.ResumeTiming();
    for (std::size_t k = 1; k <= kFirstCalls; ++k) {
      const std::size_t s = sample(k);
      const long faults_before = thread_page_faults();
      const auto t0 = Clock::now();
      const Status st =
          with_sensor ? estimator.update(stamp(k, tr), tr.q[s], tr.dq[s], tr.tau[s], tr.ft_S[s])
                      : estimator.update(stamp(k, tr), tr.q[s], tr.dq[s], tr.tau[s]);
      const auto t1 = Clock::now();
      faults[k - 1] = thread_page_faults() - faults_before;
      benchmark::DoNotOptimize(st);
      ns[k - 1] = std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
      if (first_contact == kFirstCalls && estimator.result().contact) first_contact = k - 1;
    }
  }
  if (first_contact == kFirstCalls) {
    state.SkipWithError("no contact declared in the first updates");
    return;
  }
  const auto worst = std::max_element(ns.begin(), ns.end());
  state.counters["first_ns"] = static_cast<double>(ns.front());
  state.counters["first_faults"] = static_cast<double>(faults.front());
  state.counters["contact_at"] = static_cast<double>(first_contact + 1);
  state.counters["first_contact_ns"] = static_cast<double>(ns[first_contact]);
  state.counters["first_contact_faults"] = static_cast<double>(faults[first_contact]);
  state.counters["worst_ns"] = static_cast<double>(*worst);
  state.counters["worst_at"] = static_cast<double>(worst - ns.begin() + 1);
  long total_faults = 0;
  for (const long f : faults) total_faults += f;
  state.counters["faults"] = static_cast<double>(total_faults);
  std::nth_element(ns.begin(), ns.begin() + kFirstCalls / 2, ns.end());
  state.counters["median_ns"] = static_cast<double>(ns[kFirstCalls / 2]);
}

}  // namespace

void register_contact_benchmarks() {
  const PaperArm& arm = paper_arm();
  const Trajectory& link6 = link6_trajectory();
  for (const Config& c : kTableI) {
    benchmark::RegisterBenchmark(
        (std::string("BM_FullUpdate_Ours/") + c.name + "/capsules").c_str(),
        [&arm, &link6, c](benchmark::State& state) {
          run_update(state, arm.model, arm.geometry, options_for(c, link6), link6);
        });
  }
  // Thresholds that follow |q̇| (a calibration's detection.tau_per_speed): the detector's extra
  // per-sample work, against the constant thresholds above in the same binary. b is small so
  // that the contact stays declared and every timed sample takes the full path.
  for (const Config& c : {kTableI[0], kTableI[4]}) {
    benchmark::RegisterBenchmark(
        (std::string("BM_FullUpdate_Ours/") + c.name + "/capsules/speed_thresholds").c_str(),
        [&arm, &link6, c](benchmark::State& state) {
          EstimatorOptions o = options_for(c, link6);
          o.detection.tau_per_speed = VectorX::Constant(1, 0.01);
          run_update(state, arm.model, arm.geometry, o, link6);
        });
  }
  // Thresholds that also follow the dynamic torque (detection.inertial_margin): τ_dyn and its
  // share, against the speed thresholds above. c is small so that the contact stays declared.
  for (const Config& c : {kTableI[0], kTableI[4]}) {
    benchmark::RegisterBenchmark(
        (std::string("BM_FullUpdate_Ours/") + c.name + "/capsules/inertial_margin").c_str(),
        [&arm, &link6, c](benchmark::State& state) {
          EstimatorOptions o = options_for(c, link6);
          o.detection.tau_per_speed = VectorX::Constant(1, 0.01);
          o.detection.inertial_margin = VectorX::Constant(1, 0.01);
          run_update(state, arm.model, arm.geometry, o, link6);
        });
  }
  // The residual filter (observer.residual_cutoff) and the velocity filter (observer.velocity_
  // cutoff: the momentum's q̇ through the same two sections), 20 Hz on every joint: their
  // per-sample cost against the plain update above in the same binary.
  struct Filter {
    const char* name;
    VectorX EstimatorOptions::*cutoff;
  };
  for (const Filter f : {Filter{"residual_filter", &EstimatorOptions::residual_cutoff},
                         Filter{"velocity_filter", &EstimatorOptions::velocity_cutoff}}) {
    for (const Config& c : {kTableI[0], kTableI[4]}) {
      benchmark::RegisterBenchmark(
          (std::string("BM_FullUpdate_Ours/") + c.name + "/capsules/" + f.name).c_str(),
          [&arm, &link6, c, f](benchmark::State& state) {
            EstimatorOptions o = options_for(c, link6);
            o.*f.cutoff = VectorX::Constant(1, 20.0);
            run_update(state, arm.model, arm.geometry, o, link6);
          });
    }
  }
  // Everything a calibration brings (issue 10, acceptance 5): tanh friction with per-joint
  // smoothing and offsets, thresholds that follow |q̇|, the residual and velocity filters on joints
  // 1-4 and an inertia correction; against the plain update above in the same binary.
  for (const Config& c : {kTableI[0], kTableI[4]}) {
    benchmark::RegisterBenchmark(
        (std::string("BM_FullUpdate_Ours/") + c.name + "/capsules/calibrated").c_str(),
        [&arm, &link6, c](benchmark::State& state) {
          EstimatorOptions o = options_for(c, link6);
          const int n = arm.model.nq();
          JointFriction f = JointFriction::none(n);
          f.sign = SmoothSign::kTanh;
          f.viscous = VectorX::Constant(n, 0.01);
          f.coulomb = VectorX::Constant(n, 0.01);
          f.offset = VectorX::Constant(n, 0.001);
          f.joint_smoothing = VectorX::Constant(n, 0.05);
          o.friction = f;
          o.detection.tau_per_speed = VectorX::Constant(1, 0.01);
          o.residual_cutoff = VectorX{{20, 20, 20, 20, 0, 0, 0}};
          o.velocity_cutoff = VectorX{{20, 20, 20, 20, 0, 0, 0}};
          o.inertia_correction = VectorX::Constant(n, 0.01);
          run_update(state, arm.model, arm.geometry, o, link6);
        });
  }
  if (const MeshArm* panda = panda_arm(); panda != nullptr) {
    const Trajectory& tr = *panda_trajectory();
    for (const Config& c : {kTableI[0], kTableI[4]}) {
      benchmark::RegisterBenchmark(
          (std::string("BM_FullUpdate_Ours/") + c.name + "/panda_meshes").c_str(),
          [panda, &tr, c](benchmark::State& state) {
            run_update(state, panda->model, panda->geometry, options_for(c, tr), tr);
          });
      // The paper's isolation rule on the same meshes: the cost of geometry isolation (issue 9)
      // is the ratio of the two in the same binary.
      benchmark::RegisterBenchmark(
          (std::string("BM_FullUpdate_Ours/") + c.name + "/panda_meshes/residual_isolation")
              .c_str(),
          [panda, &tr, c](benchmark::State& state) {
            EstimatorOptions o = options_for(c, tr);
            o.isolation.rule = IsolationRule::kResidual;
            run_update(state, panda->model, panda->geometry, o, tr);
          });
    }
  }
  // The first updates of a new estimator, on capsules and on the Panda's meshes.
  for (const Config& c : {kTableI[0], kTableI[4]}) {
    benchmark::RegisterBenchmark(
        (std::string("BM_FirstUpdates_Ours/") + c.name + "/capsules").c_str(),
        [&arm, &link6, c](benchmark::State& state) {
          first_updates(state, arm.model, arm.geometry, options_for(c, link6), link6);
        })
        ->Iterations(1);
    if (const MeshArm* panda = panda_arm(); panda != nullptr) {
      const Trajectory& tr = *panda_trajectory();
      benchmark::RegisterBenchmark(
          (std::string("BM_FirstUpdates_Ours/") + c.name + "/panda_meshes").c_str(),
          [panda, &tr, c](benchmark::State& state) {
            first_updates(state, panda->model, panda->geometry, options_for(c, tr), tr);
          })
          ->Iterations(1);
    }
  }
  // Latency distributions: our full F/T unknown-point update, and KDL's estimator for contrast.
  benchmark::RegisterBenchmark(
      "BM_Latency_Ours/ft/pure_force/capsules",
      [&arm, &link6](benchmark::State& state) {
        Replay replay(arm.model, arm.geometry, options_for(kTableI[0], link6), link6);
        measure_latency(state, kLatencyCalls, [&] { benchmark::DoNotOptimize(replay.step()); });
        report(state, replay, 0.0);
        state.counters.erase("allocs");
      })
      ->Iterations(1)
      ->Repetitions(1)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark(
      "BM_Latency_Kdl/JntToExtWrench",
      [&arm](benchmark::State& state) {
        const Trajectory& tr = flange_trajectory();
        const KDL::Vector g(arm.model.gravity.x(), arm.model.gravity.y(), arm.model.gravity.z());
        KDL::ChainExternalWrenchEstimator estimator(arm.chain, g, 1.0 / tr.dt, kGain, 0.0);
        (void)estimator.setInitialMomentum(tr.kq[0], tr.kdq[0]);
        KDL::Wrench w;
        std::size_t k = 1;
        measure_latency(state, kKdlLatencyCalls, [&] {
          const std::size_t s = sample(k++);
          benchmark::DoNotOptimize(estimator.JntToExtWrench(tr.kq[s], tr.kdq[s], tr.ktau[s], w));
        });
      })
      ->Iterations(1)
      ->Repetitions(1)
      ->Unit(benchmark::kMillisecond);
  // The machine's own tail: a dependent chain of multiply-adds as long as the update above
  // (~1.8 µs), no memory, no branches that depend on data. Whatever its p99.9 / median is, no
  // code of that length can do better on this machine (BENCHMARKS.md, "Jitter").
  benchmark::RegisterBenchmark("BM_Latency_Spin/1080_fma",
                               [](benchmark::State& state) {
                                 double x = 1.0001;
                                 measure_latency(state, kLatencyCalls, [&] {
                                   for (int k = 0; k < 1080; ++k) x = x * 1.0000001 + 1e-9;
                                   benchmark::DoNotOptimize(x);
                                 });
                               })
      ->Iterations(1)
      ->Repetitions(1)
      ->Unit(benchmark::kMillisecond);
}

}  // namespace extwrench::bench
