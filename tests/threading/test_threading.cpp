// Thread safety: one const Model (and one GeometryModel, meshes included) shared by every
// thread, one workspace (Data, MomentumObserver, ContactEstimator) per thread. Every thread's
// results must be bit-identical to a single-threaded run of the same inputs. The threads start
// together (a latch) so that they really overlap on the shared objects.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>
#include <latch>
#include <thread>
#include <vector>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/observer/momentum_observer.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

constexpr int kThreads = 4;  // more threads than this machine's 2 cores: preemption mid-call too

const RobotDescription& paper_arm() {
  static const RobotDescription robot =
      load_robot(std::filesystem::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf");
  return robot;
}

// Bitwise equality of doubles (NaN == NaN when the bits match): "identical", not "close".
bool bit_identical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

template <class Derived>
void append(std::vector<double>& out, const Eigen::DenseBase<Derived>& x) {
  for (Eigen::Index i = 0; i < x.size(); ++i) out.push_back(x.derived().data()[i]);
}

/// Runs `work` on kThreads threads started together; returns each thread's output.
std::vector<std::vector<double>> run_concurrently(const std::function<std::vector<double>()>& work) {
  std::vector<std::vector<double>> outputs(kThreads);
  std::latch start(kThreads);
  std::vector<std::thread> threads;
  for (int k = 0; k < kThreads; ++k) {
    threads.emplace_back([&, k] {
      start.arrive_and_wait();
      outputs[static_cast<std::size_t>(k)] = work();
    });
  }
  for (std::thread& t : threads) t.join();
  return outputs;
}

struct States {
  std::vector<VectorX> q, dq, ddq, tau;
};

States seeded_states(int n, int count, unsigned seed) {
  test::SeededRng rng(seed);
  States s;
  for (int k = 0; k < count; ++k) {
    s.q.push_back(rng.uniform_vector(n, -2.0, 2.0));
    s.dq.push_back(rng.uniform_vector(n, -1.5, 1.5));
    s.ddq.push_back(rng.uniform_vector(n, -3.0, 3.0));
    s.tau.push_back(rng.uniform_vector(n, -20.0, 20.0));
  }
  return s;
}

TEST(Threading, DynamicsOnASharedConstModelMatchSingleThreadedBitForBit) {
  const Model& model = paper_arm().model;
  const States s = seeded_states(model.nq(), 2000, 11);
  const ExternalWrench contact{model.nq(), Vector3(3.0, -2.0, 5.0), Vector3(0.1, 0.2, 0.9),
                               Vector3(0.1, 0.0, -0.2)};
  auto work = [&] {
    Data data(model);  // the only mutable state: one per thread
    std::vector<double> out;
    for (std::size_t k = 0; k < s.q.size(); ++k) {
      append(out, rnea(model, data, s.q[k], s.dq[k], s.ddq[k], std::span(&contact, 1)));
      append(out, data.root_wrench_W);
      append(out, crba(model, data, s.q[k]));
      momentum_terms(model, data, s.q[k], s.dq[k]);
      append(out, data.momentum);
      append(out, data.coriolis_transpose_dq);
      append(out, data.gravity_torque);
      append(out, body_jacobian(model, data, model.nq()));
    }
    return out;
  };
  const std::vector<double> reference = work();
  ASSERT_FALSE(reference.empty());
  const auto outputs = run_concurrently(work);
  for (int k = 0; k < kThreads; ++k) {
    EXPECT_TRUE(bit_identical(outputs[static_cast<std::size_t>(k)], reference)) << "thread " << k;
  }
}

TEST(Threading, OneMomentumObserverPerThreadMatchesSingleThreadedBitForBit) {
  const Model& model = paper_arm().model;  // each observer copies it; the original stays shared
  const States s = seeded_states(model.nq(), 3000, 12);
  auto work = [&] {
    MomentumObserver observer(model, 100.0);
    std::vector<double> out;
    EXPECT_TRUE(observer.reset(0.0, s.q[0], s.dq[0], s.tau[0]).ok());
    for (std::size_t k = 1; k < s.q.size(); ++k) {
      EXPECT_TRUE(observer.update(static_cast<double>(k) * 1e-3, s.q[k], s.dq[k], s.tau[k]).ok());
      append(out, observer.residual());
    }
    return out;
  };
  const std::vector<double> reference = work();
  ASSERT_EQ(reference.size(), (s.q.size() - 1) * static_cast<std::size_t>(model.nq()));
  const auto outputs = run_concurrently(work);
  for (int k = 0; k < kThreads; ++k) {
    EXPECT_TRUE(bit_identical(outputs[static_cast<std::size_t>(k)], reference)) << "thread " << k;
  }
}

}  // namespace
}  // namespace extwrench
