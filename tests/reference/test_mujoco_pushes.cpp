// Issue 9, acceptance 1, in closed loop: MuJoCo simulates the robot (its own MJCF compiler,
// integrator, joint damping and armature) held by the computed-torque controller at a random
// configuration, and pushes it with 15 N (xfrc_applied) at a point of a link's outward-reachable
// surface, normal to it or 30° off it (tests/reference/surface_pushes.hpp), for 250 ms. The
// estimator sees only what a real robot reports through the bridge: q, q̇, the applied torque and
// MuJoCo's base force/torque sensor (0.05 N / 0.005 N·m noise). Figures, over the samples from
// 50 ms after the push's onset to its end:
// - right link: the estimator declares the contact on the pushed link;
// - surface point: distance from the estimated surface point to the pushed point (fixed on the
//   link; +inf when no point is reported);
// - release (base F/T): time from the push's end to the first sample without a declared contact;
// - false alarms: declared contacts before the push, from 50 ms after the start.
// The shared Panda MJCF (collision meshes, MuJoCo's compiled vertices) on links 1–7 and the paper
// arm's MJCF twin (capsules) on links 2–7, at least 20 pushes per link.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/bridges/mujoco_engine.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/scenario_config.hpp"
#include "reference/surface_pushes.hpp"
#include "support/io_test_util.hpp"

namespace extwrench {
namespace {

constexpr double kForce = 15.0;         // [N]
constexpr int kPushesPerLink = 20;      // half normal, half 30° off
constexpr double kOnset = 0.15;         // [s] push from kOnset to kEnd (5 ms ramps)
constexpr double kEnd = 0.40;           // [s]
constexpr double kDuration = 0.45;      // [s]
constexpr double kSettled = 0.05;       // [s] samples counted from onset + this
constexpr double kForceNoise = 0.05;    // σ of the sensor force [N] per axis
constexpr double kMomentNoise = 0.005;  // σ of the sensor moment [N m] per axis

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return INFINITY;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

struct Figures {
  int samples = 0, right = 0, false_alarms = 0;
  std::vector<double> point_error;  // [m], +inf when no point
  std::vector<double> release;      // [s] per push
  [[nodiscard]] double right_fraction() const { return samples ? double(right) / samples : 0.0; }
  [[nodiscard]] double point_quantile(double q) const { return quantile(point_error, q); }
  [[nodiscard]] double released_within(double t) const {
    return release.empty() ? 0.0
                           : double(std::count_if(release.begin(), release.end(),
                                                  [t](double r) { return r <= t + 1e-9; })) /
                                 static_cast<double>(release.size());
  }
  void add(const Figures& o) {
    samples += o.samples;
    right += o.right;
    false_alarms += o.false_alarms;
    point_error.insert(point_error.end(), o.point_error.begin(), o.point_error.end());
    release.insert(release.end(), o.release.begin(), o.release.end());
  }
};

struct Scheme {
  const char* name;
  SensorType sensor;
  int first_link;  // the acceptance counts links first_link … n
};

constexpr Scheme kSchemes[] = {{"ft", SensorType::kForceTorque, 1},
                               {"force sensor", SensorType::kForce, 4},
                               {"no sensor", SensorType::kNone, 6}};

/// The scenario of one push: the robot held at the push's configuration, the push as a force
/// fixed in the world at a point fixed on the link, the base F/T sensor with noise.
Scenario push_scenario(const RobotDescription& robot, const std::filesystem::path& mjcf,
                       const test::ReachablePush& push, std::uint64_t seed) {
  Scenario s;
  s.source = "test_mujoco_pushes";
  s.robot_path = mjcf;
  s.robot = robot;
  s.engine = Scenario::Engine::kMujoco;
  sim::SimulationConfig& c = s.simulation;
  c.duration = kDuration;
  c.sample_time = 1e-3;
  c.substeps = 2;
  c.noise_seed = seed;
  c.sensor.type = SensorType::kForceTorque;
  c.sensor.X_WS = default_sensor_pose(robot.model);
  c.sensor.force_noise_S = Vector3::Constant(kForceNoise);
  c.sensor.moment_noise_S = Vector3::Constant(kMomentNoise);
  c.q0 = push.q;
  c.dq0 = VectorX::Zero(push.q.size());
  sim::ForceProfile f;
  f.frame = robot.model.bodies[static_cast<std::size_t>(push.link)].name;
  f.axes = sim::ForceProfile::Axes::kWorld;
  f.force = kForce * push.u_W;
  f.point_F = push.p_B;
  f.start = kOnset;
  f.end = kEnd;
  f.ramp = 0.005;
  f.resolve(robot.model);
  c.forces.push_back(f);
  const int n = robot.model.nq();
  s.trajectory = {push.q, VectorX::Zero(n), VectorX::Zero(n), VectorX::Zero(n)};
  s.gains = sim::pid_gains_triple_pole(n, 10.0);
  return s;
}

/// Whether case D (a 3-axis base force sensor) can estimate the pushed link's moment: J_ω of its
/// joints has rank 3 within the solver's default condition bound (κ ≤ 1e3).
bool case_d_observable(const Model& model, const test::ReachablePush& push) {
  Data data(model);
  forward_kinematics(model, data, push.q);
  Matrix6X J(6, model.nq());
  point_jacobian(model, data, push.link, data.X_WB[static_cast<std::size_t>(push.link)].translation,
                 J);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J.bottomRows<3>().leftCols(push.link));
  const VectorX& sv = svd.singularValues();
  return sv.size() == 3 && sv[2] > sv[0] / SolverOptions{}.max_condition;
}

/// One push in MuJoCo, estimated by one estimator per scheme; adds its figures to `out`.
void run_push(const RobotDescription& robot, const std::filesystem::path& mjcf,
              const test::ReachablePush& push, std::uint64_t seed,
              std::vector<std::vector<Figures>>& out) {
  const Scenario s = push_scenario(robot, mjcf, push, seed);
  mujoco::MujocoSimulator simulator(
      s, sim::ComputedTorqueController(robot.model, s.trajectory, s.gains), s.simulation);
  std::vector<ContactEstimator> estimators;
  for (const Scheme& scheme : kSchemes) {
    EstimatorOptions opt;
    opt.sensor.type = scheme.sensor;
    opt.sensor.X_WS = s.simulation.sensor.X_WS;
    estimators.emplace_back(robot.model, robot.geometry, opt);
  }
  std::vector<Figures> f(std::size(kSchemes));
  std::vector<double> released(std::size(kSchemes), INFINITY);
  Data data(robot.model);
  Sample sample;
  for (bool first = true; simulator.next(sample); first = false) {
    forward_kinematics(robot.model, data, sample.q);
    const Vector3 p_W = data.X_WB[static_cast<std::size_t>(push.link)].act(push.p_B);
    for (std::size_t k = 0; k < estimators.size(); ++k) {
      Sample input = sample;
      input.has_moment = kSchemes[k].sensor == SensorType::kForceTorque;
      input.has_force = kSchemes[k].sensor != SensorType::kNone;
      const Status status = first ? estimators[k].reset(input) : estimators[k].update(input);
      ASSERT_TRUE(status.ok()) << kSchemes[k].name << " t = " << sample.t << ": "
                               << to_string(status.code) << " " << to_string(status.channel);
      const ContactEstimate& e = estimators[k].result();
      if (sample.t >= kSettled && sample.t < kOnset && e.contact) ++f[k].false_alarms;
      if (sample.t >= kOnset + kSettled && sample.t <= kEnd) {
        ++f[k].samples;
        if (e.contact && e.link == push.link) ++f[k].right;
        f[k].point_error.push_back(e.point_W.allFinite() ? (e.point_W - p_W).norm() : INFINITY);
      }
      if (sample.t > kEnd && !e.contact && !std::isfinite(released[k])) released[k] = sample.t;
    }
  }
  for (std::size_t k = 0; k < f.size(); ++k) {
    f[k].release.push_back(released[k] - kEnd);
    // Case D is observable when J_ω of the link's joints has rank 3 (κ within the solver's bound).
    if (kSchemes[k].sensor == SensorType::kForce && !case_d_observable(robot.model, push)) continue;
    out[k][static_cast<std::size_t>(push.link)].add(f[k]);
  }
}

void report(const std::string& what, const Figures& f) {
  std::printf(
      "%-22s samples %5d  right link %5.1f %%  point median %6.1f mm  p95 %7.1f mm  "
      "false alarms %d  release <= 5 ms %5.1f %% (median %.0f ms, worst %.0f ms)\n",
      what.c_str(), f.samples, 100.0 * f.right_fraction(), 1e3 * f.point_quantile(0.5),
      1e3 * f.point_quantile(0.95), f.false_alarms, 100.0 * f.released_within(0.005),
      1e3 * quantile(f.release, 0.5), 1e3 * quantile(f.release, 1.0));
}

/// The right-link share each scheme must reach (ft, force sensor, no sensor) and the share of
/// base-F/T pushes released within 5 ms: the acceptance's 0.95, 0.95, 0.90 and 1 (both robots
/// meet them). A robot that did not would hold the figure measured here, with the reason.
struct Bounds {
  double right[3] = {0.95, 0.95, 0.90};
  double released_5ms = 1.0;
  double worst_release = 0.005;  // [s]
};

/// Every link from `first_link` pushed kPushesPerLink times; per scheme, the figures of its links.
void acceptance(const std::filesystem::path& mjcf, int first_link, std::uint64_t seed,
                const Bounds& bounds) {
  mujoco::register_mjcf_loader();
  mujoco::register_mujoco_engine();
  const RobotDescription robot = mujoco::load_mjcf(mjcf);
  const int n = robot.model.nq();
  ASSERT_EQ(n, 7);
  Data data(robot.model);
  const test::BodyPoses poses = [&](const VectorX& q) {
    forward_kinematics(robot.model, data, q);
    return data.X_WB;
  };
  Rng rng(seed);
  std::vector<std::vector<Figures>> figures(std::size(kSchemes),
                                            std::vector<Figures>(static_cast<std::size_t>(n + 1)));
  for (int l = first_link; l <= n; ++l) {
    const std::vector<test::ReachablePush> pushes =
        test::make_reachable_pushes(robot, poses, l, kPushesPerLink, rng);
    EXPECT_GE(static_cast<int>(pushes.size()), kPushesPerLink) << "link " << l;
    for (std::size_t i = 0; i < pushes.size(); ++i) {
      run_push(robot, mjcf, pushes[i], seed * 1000 + 10 * l + i, figures);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  for (std::size_t k = 0; k < std::size(kSchemes); ++k) {
    const Scheme& scheme = kSchemes[k];
    Figures all;
    for (int l = std::max(first_link, scheme.first_link); l <= n; ++l) {
      const Figures& f = figures[k][static_cast<std::size_t>(l)];
      report(std::string(scheme.name) + " link " + std::to_string(l), f);
      all.add(f);
    }
    report(std::string(scheme.name) + " all", all);
    EXPECT_EQ(all.false_alarms, 0) << scheme.name;
    EXPECT_GE(all.right_fraction(), bounds.right[k]) << scheme.name;
    if (scheme.sensor == SensorType::kNone) continue;
    EXPECT_LE(all.point_quantile(0.5), 0.01) << scheme.name;
    EXPECT_LE(all.point_quantile(0.95), 0.03) << scheme.name;
    if (scheme.sensor == SensorType::kForceTorque) {
      EXPECT_GE(all.released_within(0.005), bounds.released_5ms) << scheme.name;  // acceptance 4
      EXPECT_LE(quantile(all.release, 1.0), bounds.worst_release + 1e-9)
          << scheme.name;  // t - t_end
    }
  }
}

TEST(MujocoPushes, PandaMeshesFindThePushedLinkAndPoint) {
  const std::filesystem::path mjcf =
      test::shared_models() /
      "franka_panda/mjcf_menagerie/derived/panda_nohand_collision_only_mj222.xml";
  if (!std::filesystem::exists(mjcf)) GTEST_SKIP() << "shared models absent";
  acceptance(mjcf, 1, 9101, Bounds{});
}

TEST(MujocoPushes, PaperArmCapsulesFindThePushedLinkAndPoint) {
  acceptance(test::project_models() / "paper_arm.xml", 2, 9102, Bounds{});
}

}  // namespace
}  // namespace extwrench
