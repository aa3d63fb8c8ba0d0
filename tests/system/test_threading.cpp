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
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
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
std::vector<std::vector<double>> run_concurrently(
    const std::function<std::vector<double>()>& work) {
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
  const Model& model = paper_arm().model;  // shared, read-only; each thread owns its Data
  const States s = seeded_states(model.nq(), 3000, 12);
  auto work = [&] {
    MomentumObserver observer(model, 100.0);
    Data data(model);
    std::vector<double> out;
    EXPECT_TRUE(observer.reset(model, data, 0.0, s.q[0], s.dq[0], s.tau[0]).ok());
    for (std::size_t k = 1; k < s.q.size(); ++k) {
      EXPECT_TRUE(
          observer.update(model, data, static_cast<double>(k) * 1e-3, s.q[k], s.dq[k], s.tau[k])
              .ok());
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

// The whole estimator, F/T sensor and unknown point, so that every stage runs (residual, q̈̂,
// base RNEA, isolation, case C, the line meeting the link's shapes). The robot description —
// Panda meshes and their ray casters included when /work/shared is present — is shared const;
// each thread builds its own ContactEstimator from it.
void expect_estimators_match(const RobotDescription& robot, int contact_body,
                             const Vector3& point_B, const Vector3& force_B) {
  const Model& model = robot.model;
  const int n = model.nq();
  // A smooth motion with a constant push on `contact_body`; τ and the base reading from RNEA.
  std::vector<VectorX> q, dq, tau;
  std::vector<Vector6> reading;
  {
    Data data(model);
    for (int k = 0; k < 1500; ++k) {
      const double t = k * 1e-3;
      VectorX qk(n), dqk(n), ddqk(n);
      for (int i = 0; i < n; ++i) {
        const double w = 2.0 + 0.5 * i;
        qk[i] = 0.5 + 0.3 * std::sin(w * t + i);
        dqk[i] = 0.3 * w * std::cos(w * t + i);
        ddqk[i] = -0.3 * w * w * std::sin(w * t + i);
      }
      forward_kinematics(model, data, qk);
      const Pose& X = data.X_WB[static_cast<std::size_t>(contact_body)];
      const ExternalWrench w{contact_body, X.rotation * force_B, X.act(point_B), Vector3::Zero()};
      rnea_no_kinematics(model, data, dqk, ddqk, std::span(&w, 1));
      q.push_back(qk);
      dq.push_back(dqk);
      tau.push_back(data.tau);
      reading.push_back(sensor_reading(data, Pose::identity()));
    }
  }
  EstimatorOptions options;
  options.sensor.type = SensorType::kForceTorque;
  options.contact.model = ContactModel::kPureForce;
  // The paper's rule: this test is about threads sharing the meshes, its push point is not on
  // the link's surface (geometry isolation: test_geometry_isolation).
  options.isolation.rule = IsolationRule::kResidual;
  auto work = [&] {
    ContactEstimator estimator(model, robot.geometry, options);
    std::vector<double> out;
    EXPECT_TRUE(estimator.reset(0.0, q[0], dq[0], tau[0]).ok());
    for (std::size_t k = 1; k < q.size(); ++k) {
      EXPECT_TRUE(
          estimator.update(static_cast<double>(k) * 1e-3, q[k], dq[k], tau[k], reading[k]).ok());
      const ContactEstimate& e = estimator.result();
      out.push_back(e.link);
      out.push_back(e.flags);
      append(out, e.force_W);
      append(out, e.point_W);
      append(out, e.line_point_W);
      append(out, e.residual);
    }
    // Last: did the run exercise the full path (contact declared on the right link, a point)?
    const ContactEstimate& last = estimator.result();
    out.push_back(last.contact && last.link == contact_body &&
                  last.has(EstimateFlag::kLineOfAction));
    return out;
  };
  const std::vector<double> reference = work();
  ASSERT_FALSE(reference.empty());
  EXPECT_EQ(reference.back(), 1.0) << "the single-threaded run did not locate the contact";
  const auto outputs = run_concurrently(work);
  for (int k = 0; k < kThreads; ++k) {
    EXPECT_TRUE(bit_identical(outputs[static_cast<std::size_t>(k)], reference)) << "thread " << k;
  }
}

TEST(Threading, OneContactEstimatorPerThreadOnSharedCapsulesMatchesSingleThreaded) {
  // Link 6's capsule (radius 0.065 m) of models/paper_arm.urdf, pushed inward.
  expect_estimators_match(paper_arm(), 6, Vector3(0.065, 0.0, 0.01), Vector3(-15.0, 0.0, 30.0));
}

TEST(Threading, OneContactEstimatorPerThreadOnSharedPandaMeshesMatchesSingleThreaded) {
  const std::filesystem::path urdf =
      std::filesystem::path(EXTWRENCH_SHARED_DIR) /
      "models/franka_panda/urdf_example-robot-data/urdf/panda.relative.urdf";
  if (!std::filesystem::exists(urdf)) GTEST_SKIP() << "no " << urdf;
  RobotDescription panda = load_robot(urdf);
  // The estimator needs a serial chain: keep link 0..7 (hand merged), drop the fingers.
  const int keep = panda.model.body_index("panda_link7") + 1;
  panda.model.bodies.resize(static_cast<std::size_t>(keep));
  panda.model.joints.resize(static_cast<std::size_t>(keep));
  panda.model.parents.resize(static_cast<std::size_t>(keep));
  std::erase_if(panda.model.frames, [&](const Frame& f) { return f.body >= keep; });
  GeometryModel g;
  g.body_shapes.resize(static_cast<std::size_t>(keep));
  for (const CollisionShape& shape : panda.geometry.shapes) {
    if (shape.body >= keep) continue;
    g.body_shapes[static_cast<std::size_t>(shape.body)].push_back(
        static_cast<int>(g.shapes.size()));
    g.shapes.push_back(shape);
  }
  panda.geometry = std::move(g);
  // A vertex of link 6's mesh farthest along +x, pushed along −x (into the mesh) and +y.
  Vector3 point = Vector3::Constant(-1e9);
  for (int s : panda.geometry.body_shapes[6]) {
    const CollisionShape& shape = panda.geometry.shapes[static_cast<std::size_t>(s)];
    ASSERT_TRUE(shape.mesh);
    for (Eigen::Index v = 0; v < shape.mesh->vertices.cols(); ++v) {
      const Vector3 p = shape.placement.act(shape.mesh->vertices.col(v));
      if (p.x() > point.x()) point = p;
    }
  }
  expect_estimators_match(panda, 6, point, Vector3(-15.0, 30.0, 0.0));
}

}  // namespace
}  // namespace extwrench
