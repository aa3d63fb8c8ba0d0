// Core dynamics, ours against KDL 1.5.1 on the paper's arm and the same seeded states.
// Each benchmark cycles through StatePool's states (so the branch predictor cannot learn one
// input) and reports "allocs", heap allocations per call counted after the timed loop.
#include <benchmark/benchmark.h>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "robots.hpp"

namespace extwrench::bench {
namespace {

constexpr std::size_t kMask = StatePool::kNumStates - 1;
static_assert((StatePool::kNumStates & kMask) == 0, "state pool size must be a power of two");

KDL::Vector kdl_gravity(const Model& model) {
  return {model.gravity.x(), model.gravity.y(), model.gravity.z()};
}

// ---- RNEA ---------------------------------------------------------------------------------

void BM_Rnea_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  auto call = [&](std::size_t k) {
    k &= kMask;
    benchmark::DoNotOptimize(rnea(arm.model, data, s.q[k], s.dq[k], s.ddq[k]).data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Rnea_Ours);

// Joint torques and the base sensor's wrench (the base iteration down to link 0, f_m = −f_0,
// docs/method.md).
void BM_RneaBaseWrench_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  const Pose X_WS = Pose::identity();
  auto call = [&](std::size_t k) {
    k &= kMask;
    benchmark::DoNotOptimize(rnea(arm.model, data, s.q[k], s.dq[k], s.ddq[k]).data());
    Vector6 reading = sensor_reading(data, X_WS);
    benchmark::DoNotOptimize(reading.data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_RneaBaseWrench_Ours);

void BM_Rnea_Kdl(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  KDL::ChainIdSolver_RNE solver(arm.chain, kdl_gravity(arm.model));
  KDL::Wrenches f_ext(arm.chain.getNrOfSegments(), KDL::Wrench::Zero());
  KDL::JntArray tau(arm.chain.getNrOfJoints());
  auto call = [&](std::size_t k) {
    k &= kMask;
    benchmark::DoNotOptimize(solver.CartToJnt(s.kq[k], s.kdq[k], s.kddq[k], f_ext, tau));
    benchmark::DoNotOptimize(tau.data.data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Rnea_Kdl);

// ---- mass matrix --------------------------------------------------------------------------

void BM_MassMatrix_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  auto call = [&](std::size_t k) {
    benchmark::DoNotOptimize(crba(arm.model, data, s.q[k & kMask]).data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_MassMatrix_Ours);

void BM_MassMatrix_Kdl(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  KDL::ChainDynParam solver(arm.chain, kdl_gravity(arm.model));
  KDL::JntSpaceInertiaMatrix M(arm.chain.getNrOfJoints());
  auto call = [&](std::size_t k) {
    benchmark::DoNotOptimize(solver.JntToMass(s.kq[k & kMask], M));
    benchmark::DoNotOptimize(M.data.data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_MassMatrix_Kdl);

// ---- Jacobian of the flange (both include the forward kinematics) -------------------------

void BM_Jacobian_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  const int tip = arm.model.nq();
  auto call = [&](std::size_t k) {
    forward_kinematics(arm.model, data, s.q[k & kMask]);
    benchmark::DoNotOptimize(body_jacobian(arm.model, data, tip).data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Jacobian_Ours);

// The same Jacobian after forward_poses: the poses without the world mass properties.
void BM_JacobianPoses_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  const int tip = arm.model.nq();
  auto call = [&](std::size_t k) {
    forward_poses(arm.model, data, s.q[k & kMask]);
    benchmark::DoNotOptimize(body_jacobian(arm.model, data, tip).data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_JacobianPoses_Ours);

void BM_Jacobian_Kdl(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  KDL::ChainJntToJacSolver solver(arm.chain);
  KDL::Jacobian J(arm.chain.getNrOfJoints());
  auto call = [&](std::size_t k) {
    benchmark::DoNotOptimize(solver.JntToJac(s.kq[k & kMask], J));
    benchmark::DoNotOptimize(J.data.data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Jacobian_Kdl);

// ---- gravity g(q) and the Coriolis torques -------------------------------------------------

// The gravity pass of issue 15: subtree masses and first moments in body frames, no velocity.
void BM_Gravity_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  auto call = [&](std::size_t k) {
    benchmark::DoNotOptimize(gravity_torques(arm.model, data, s.q[k & kMask]).data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Gravity_Ours);

// What gravity_torques ran before issue 15 (the reference the pass must beat by 2x): forward
// kinematics with the world mass properties, then the whole bias pass at q_dot = q_ddot = 0.
void BM_GravityBiasPass_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  const VectorX zero = VectorX::Zero(arm.model.nq());
  auto call = [&](std::size_t k) {
    forward_kinematics(arm.model, data, s.q[k & kMask]);
    benchmark::DoNotOptimize(rnea_no_kinematics(arm.model, data, zero, zero, {}, true).data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_GravityBiasPass_Ours);

void BM_Gravity_Kdl(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  KDL::ChainDynParam solver(arm.chain, kdl_gravity(arm.model));
  KDL::JntArray gravity(arm.chain.getNrOfJoints());
  auto call = [&](std::size_t k) {
    benchmark::DoNotOptimize(solver.JntToGravity(s.kq[k & kMask], gravity));
    benchmark::DoNotOptimize(gravity.data.data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Gravity_Kdl);

// Our closest exposed function to KDL's C(q, q_dot) q_dot: bias_torques, C q_dot + g (g too).
void BM_Bias_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  auto call = [&](std::size_t k) {
    k &= kMask;
    benchmark::DoNotOptimize(bias_torques(arm.model, data, s.q[k], s.dq[k]).data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Bias_Ours);

void BM_Coriolis_Kdl(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  KDL::ChainDynParam solver(arm.chain, kdl_gravity(arm.model));
  KDL::JntArray coriolis(arm.chain.getNrOfJoints());
  auto call = [&](std::size_t k) {
    k &= kMask;
    benchmark::DoNotOptimize(solver.JntToCoriolis(s.kq[k], s.kdq[k], coriolis));
    benchmark::DoNotOptimize(coriolis.data.data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_Coriolis_Kdl);

// ---- the model terms of the residual (4): B q̇, Cᵀq̇, g ------------------------------------

// O(n) recursions over link momenta (docs/algorithms.md).
void BM_MomentumTerms_Ours(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  Data data(arm.model);
  auto call = [&](std::size_t k) {
    k &= kMask;
    momentum_terms(arm.model, data, s.q[k], s.dq[k]);
    benchmark::DoNotOptimize(data.momentum.data());
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_MomentumTerms_Ours);

// KDL's route (as in its ChainExternalWrenchEstimator): B(q), C(q, q̇) q̇, g(q).
void BM_MomentumTerms_Kdl(benchmark::State& state) {
  const PaperArm& arm = paper_arm();
  const StatePool& s = state_pool();
  KDL::ChainDynParam solver(arm.chain, kdl_gravity(arm.model));
  const unsigned n = arm.chain.getNrOfJoints();
  KDL::JntSpaceInertiaMatrix M(n);
  KDL::JntArray coriolis(n), gravity(n);
  auto call = [&](std::size_t k) {
    k &= kMask;
    benchmark::DoNotOptimize(solver.JntToMass(s.kq[k], M));
    benchmark::DoNotOptimize(solver.JntToCoriolis(s.kq[k], s.kdq[k], coriolis));
    benchmark::DoNotOptimize(solver.JntToGravity(s.kq[k], gravity));
  };
  std::size_t k = 0;
  for (auto _ : state) call(k++);
  state.counters["allocs"] =
      allocations_per_call([&](int i) { call(static_cast<std::size_t>(i)); });
}
BENCHMARK(BM_MomentumTerms_Kdl);

}  // namespace
}  // namespace extwrench::bench
