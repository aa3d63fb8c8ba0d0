// A property suite spanning several sources, so it keeps its own name (docs/layout.md, Tests).
// The real-time path allocates nothing: once a Data is made, every dynamics function runs
// without a single heap allocation. Counted by a process-wide malloc / operator new counter
// (tests/support/alloc_counter.hpp), so std::vector growth or a stray std::string is caught
// too, not only Eigen's own allocations. No warm-up call: the first call must not allocate either.
#include <gtest/gtest.h>

#include <array>
#include <span>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/model/sample_models.hpp"
#include "support/alloc_counter.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::AllocationCounter;
using test::SeededRng;

/// Number of heap allocations made while running `f`.
template <class F>
std::size_t allocations_in(F&& f) {
  const AllocationCounter counter;
  f();
  return counter.count();
}

struct Case {
  const char* name;
  RandomChainOptions options;
};

class DynamicsAllocations : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    if (!test::allocation_counting_available()) {
      GTEST_SKIP() << "allocation counting is unavailable in sanitizer builds";
    }
    model_ = random_chain(GetParam().options);
    SeededRng rng(21);
    const int n = model_.nq();
    q_ = rng.uniform_vector(n, -3, 3);
    dq_ = rng.uniform_vector(n, -2, 2);
    ddq_ = rng.uniform_vector(n, -5, 5);
    tau_ = rng.uniform_vector(n, -10, 10);
    p_W_ = rng.uniform_vector3(-1, 1);
    J_ = Matrix6X::Zero(6, n);
    const int last = model_.num_bodies() - 1;
    wrenches_[0] = {last, rng.uniform_vector3(-20, 20), rng.uniform_vector3(-1, 1),
                    rng.uniform_vector3(-2, 2)};
    wrenches_[1] = {0, rng.uniform_vector3(-20, 20), rng.uniform_vector3(-1, 1),
                    rng.uniform_vector3(-2, 2)};
    wrenches_[2] = {last / 2, rng.uniform_vector3(-20, 20), rng.uniform_vector3(-1, 1),
                    Vector3::Zero()};
    X_WS_ = Pose::from_xyz_rpy(rng.uniform_vector3(-0.5, 0.5), rng.uniform_vector3(-3, 3));
  }

  Model model_;
  VectorX q_, dq_, ddq_, tau_;
  Vector3 p_W_;
  Matrix6X J_;
  std::array<ExternalWrench, 3> wrenches_;
  Pose X_WS_;
};

TEST_P(DynamicsAllocations, ForwardKinematicsAndFramePosesAllocateNothing) {
  Data data(model_);
  EXPECT_EQ(allocations_in([&] { forward_kinematics(model_, data, q_); }), 0u);
  EXPECT_EQ(allocations_in([&] { forward_poses(model_, data, q_); }), 0u);
  const int frame = model_.num_bodies() - 1;
  Pose X;
  EXPECT_EQ(allocations_in([&] { X = frame_pose(model_, data, frame); }), 0u);
  EXPECT_TRUE(X.rotation.allFinite());
}

TEST_P(DynamicsAllocations, JacobiansAllocateNothing) {
  Data data(model_);
  forward_kinematics(model_, data, q_);
  const int body = model_.num_bodies() - 1;
  EXPECT_EQ(allocations_in([&] { point_jacobian(model_, data, body, p_W_, J_); }), 0u);
  EXPECT_EQ(allocations_in([&] { point_jacobian(model_, data, body, p_W_, data.J); }), 0u);
  EXPECT_EQ(allocations_in([&] { body_jacobian(model_, data, body); }), 0u);
  EXPECT_TRUE(J_.allFinite());
}

TEST_P(DynamicsAllocations, RneaWithAndWithoutExternalWrenchesAllocatesNothing) {
  Data data(model_);
  EXPECT_EQ(allocations_in([&] { rnea(model_, data, q_, dq_, ddq_); }), 0u);
  EXPECT_EQ(allocations_in([&] { rnea(model_, data, q_, dq_, ddq_, wrenches_); }), 0u);
  const std::span<const ExternalWrench> one(wrenches_.data(), 1);
  EXPECT_EQ(allocations_in([&] { rnea(model_, data, q_, dq_, ddq_, one); }), 0u);
  EXPECT_EQ(allocations_in([&] { rnea_no_kinematics(model_, data, dq_, ddq_); }), 0u);
  EXPECT_EQ(allocations_in([&] { rnea_no_kinematics(model_, data, dq_, ddq_, wrenches_, false); }),
            0u);
  EXPECT_TRUE(data.tau.allFinite());
}

TEST_P(DynamicsAllocations, SensorReadingsAllocateNothing) {
  Data data(model_);
  rnea(model_, data, q_, dq_, ddq_, wrenches_);
  Vector6 reading, reading_world;
  EXPECT_EQ(allocations_in([&] { reading = sensor_reading(data, X_WS_); }), 0u);
  EXPECT_EQ(allocations_in([&] { reading_world = sensor_reading_world(data, X_WS_.translation); }),
            0u);
  EXPECT_TRUE(reading.allFinite() && reading_world.allFinite());
}

TEST_P(DynamicsAllocations, BiasAndGravityTorquesAllocateNothing) {
  Data data(model_);
  EXPECT_EQ(allocations_in([&] { bias_torques(model_, data, q_, dq_); }), 0u);
  EXPECT_EQ(allocations_in([&] { gravity_torques(model_, data, q_); }), 0u);
  EXPECT_TRUE(data.gravity_torque.allFinite());
}

TEST_P(DynamicsAllocations, MassAndCoriolisMatricesAllocateNothing) {
  Data data(model_);
  EXPECT_EQ(allocations_in([&] { crba(model_, data, q_); }), 0u);
  EXPECT_EQ(allocations_in([&] { crba_no_kinematics(model_, data); }), 0u);
  EXPECT_EQ(allocations_in([&] { coriolis_matrix(model_, data, q_, dq_); }), 0u);
  EXPECT_TRUE(data.M.allFinite() && data.C.allFinite());
}

TEST_P(DynamicsAllocations, MomentumTermsAllocateNothing) {
  Data data(model_);
  EXPECT_EQ(allocations_in([&] { momentum_terms(model_, data, q_, dq_); }), 0u);
  EXPECT_EQ(allocations_in([&] { momentum_and_bias_terms(model_, data, q_, dq_); }), 0u);
  EXPECT_TRUE(data.momentum.allFinite() && data.coriolis_transpose_dq.allFinite());
}

TEST_P(DynamicsAllocations, ForwardDynamicsAllocatesNothing) {
  Data data(model_);
  bool ok = false;
  EXPECT_EQ(allocations_in([&] { ok = forward_dynamics(model_, data, q_, dq_, tau_); }), 0u);
  EXPECT_TRUE(ok);
  EXPECT_TRUE(data.ddq.allFinite());
}

TEST(AllocationCounter, SeesVectorGrowthSoTheZeroCountsAreMeaningful) {
  if (!test::allocation_counting_available()) GTEST_SKIP() << "sanitizer build";
  const std::size_t count = allocations_in([] {
    VectorX v = VectorX::Zero(40);                  // one Eigen allocation
    asm volatile("" : : "g"(v.data()) : "memory");  // keep the compiler from eliding it
  });
  EXPECT_GE(count, 1u);
}

// Sizes around Eigen's blocking thresholds (LLT switches to a blocked algorithm for larger n).
INSTANTIATE_TEST_SUITE_P(Models, DynamicsAllocations,
                         ::testing::Values(Case{"chain7", {7, false, false, 3}},
                                           Case{"tree12", {12, true, true, 4}},
                                           Case{"chain40", {40, false, true, 5}}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace extwrench
