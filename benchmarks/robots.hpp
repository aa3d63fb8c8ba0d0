// The robots and seeded states every benchmark uses, built once per process, identical for our
// library and for KDL so that each ratio compares the same computation on the same inputs.
#pragma once

#include <cstddef>
#include <kdl/chain.hpp>
#include <kdl/jntarray.hpp>
#include <string>
#include <utility>
#include <vector>

#include "extwrench/geometry/shapes.hpp"
#include "extwrench/model/model.hpp"
#include "support/alloc_counter.hpp"

namespace extwrench::bench {

/// The paper's 7R arm (Table II) for both libraries: from models/paper_arm.urdf (our loader and
/// kdl_parser::treeFromString on test::urdf_for_reference's copy: no geometry, no root inertia)
/// when the file exists, otherwise built in code from the DH table (our Model by hand, KDL's chain
/// with KDL::Frame::DH). Either way, set-up checks that KDL's RNE and ours agree on the seeded
/// states (throws otherwise).
struct PaperArm {
  Model model;
  GeometryModel geometry;  ///< collision shapes (capsules); see paper_arm()
  KDL::Chain chain;        ///< root (link 0) to the flange
  std::string source;      ///< where the robot came from, printed in the benchmark context
};
const PaperArm& paper_arm();

/// kNumStates seeded random states: q in [-2, 2] rad, dq in [-1.5, 1.5] rad/s,
/// ddq in [-3, 3] rad/s^2, tau in [-20, 20] N m; as Eigen vectors and as KDL arrays.
struct StatePool {
  static constexpr std::size_t kNumStates = 256;
  std::vector<VectorX> q, dq, ddq, tau;
  std::vector<KDL::JntArray> kq, kdq, kddq, ktau;
};
const StatePool& state_pool();

/// A robot without KDL counterpart (collision meshes): the Panda arm of /work/shared, its finger
/// bodies dropped (the estimators need a serial chain; the hand stays, merged into link 7).
struct MeshArm {
  Model model;
  GeometryModel geometry;
  std::string source;
};
/// nullptr when /work/shared's Panda is absent (the mesh benchmarks then skip).
const MeshArm* panda_arm();

/// The contact a trajectory carries: a constant wrench fixed in the frame of `body`.
struct ContactSpec {
  int body = 0;
  Vector3 point_B = Vector3::Zero();   ///< application point, body frame [m]
  Vector3 force_B = Vector3::Zero();   ///< [N], body frame
  Vector3 moment_B = Vector3::Zero();  ///< pure moment [N m], body frame
};

/// A periodic, smooth joint trajectory sampled at 1 kHz with a constant contact wrench: the
/// commanded torques τ = RNEA(q, q̇, q̈) − J_pᵀ W make the robot follow it exactly, and the base
/// F/T sensor reads the robot's discharge plus the contact. The estimator benchmarks replay it
/// with t_k = k·dt; its period is a whole number of samples, so wrapping around stays smooth.
struct Trajectory {
  static constexpr std::size_t kNumSamples = 2000;  ///< 2 s: the frequencies are 0.5 and 1 Hz
  double dt = 1e-3;
  ContactSpec contact;
  Pose X_WS;  ///< base sensor frame ("sensor", else the root)
  std::vector<VectorX> q, dq, ddq, tau;
  std::vector<Vector6> ft_S;  ///< base F/T reading [f_m; n_m] in the sensor frame
  std::vector<KDL::JntArray> kq, kdq, ktau;
};
/// Paper arm, pure force on link 6 pushing on its capsule (the paper's contact link).
const Trajectory& link6_trajectory();
/// Paper arm, force and moment at the flange (link 7's origin): KDL's estimator's assumption.
const Trajectory& flange_trajectory();
/// Panda, pure force on link 6 pushing on its collision mesh (nullptr without the Panda).
const Trajectory* panda_trajectory();

/// Registers the ContactEstimator benchmarks (one per Table I configuration, the Panda's meshes
/// when present, the latency runs); called by main after the robots loaded.
void register_contact_benchmarks();

/// Allocations per call of `f`, over `calls` calls after one warm-up call.
template <class F>
double allocations_per_call(F&& f, int calls = 1000) {
  f(0);
  const std::size_t before = test::allocation_count();
  for (int i = 0; i < calls; ++i) f(i);
  return static_cast<double>(test::allocation_count() - before) / calls;
}

}  // namespace extwrench::bench
