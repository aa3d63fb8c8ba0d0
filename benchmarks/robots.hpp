// The robots and seeded states every benchmark uses, built once per process, identical for our
// library and for KDL so that each ratio compares the same computation on the same inputs.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <kdl/chain.hpp>
#include <kdl/jntarray.hpp>

#include "alloc_counter.hpp"
#include "extwrench/geometry/shapes.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::bench {

/// The paper's 7R arm (SPEC §5) for both libraries: from models/paper_arm.urdf (our loader and
/// kdl_parser::treeFromFile) when the file exists, otherwise built in code from the DH table
/// (our Model by hand, KDL's chain with KDL::Frame::DH). Either way, set-up checks that KDL's
/// RNE and ours agree on the seeded states (throws otherwise).
struct PaperArm {
  Model model;
  GeometryModel geometry;    ///< collision shapes (capsules); see paper_arm()
  KDL::Chain chain;          ///< root (link 0) to the flange
  std::string source;        ///< where the robot came from, printed in the benchmark context
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

/// A periodic, smooth joint trajectory sampled at 1 kHz, with a constant pure force on link 6
/// (fixed in link 6's frame, applied at a point of its capsule's surface, pushing): the commanded
/// torques τ = RNEA(q, q̇, q̈) − J_pᵀ F make the robot follow it exactly, and the base F/T sensor
/// reads the robot's discharge plus the contact force. The estimator benchmarks replay it with
/// t_k = k·dt; its period is a whole number of samples, so wrapping around stays smooth.
struct Trajectory {
  static constexpr std::size_t kNumSamples = 2000;  ///< 2 s: the frequencies are 0.5 and 1 Hz
  double dt = 1e-3;
  int contact_body = 6;
  Vector3 contact_point_B{0.065, 0.0, 0.01};  ///< on link 6's capsule (r = 0.065 m), body frame
  Vector3 contact_force_B{-20.0, 4.0, 2.0};    ///< [N], body frame, into the surface
  Pose X_WS;                                   ///< base sensor frame "sensor"
  std::vector<VectorX> q, dq, ddq, tau;
  std::vector<Vector6> ft_S;                   ///< base F/T reading [f_m; n_m] in the sensor frame
  std::vector<KDL::JntArray> kq, kdq, ktau;
};
const Trajectory& trajectory();

/// Allocations per call of `f`, over `calls` calls after one warm-up call.
template <class F>
double allocations_per_call(F&& f, int calls = 1000) {
  f(0);
  const std::size_t before = allocation_count();
  for (int i = 0; i < calls; ++i) f(i);
  return static_cast<double>(allocation_count() - before) / calls;
}

}  // namespace extwrench::bench
