// Desired joint trajectories for the closed-loop simulator.
#pragma once

#include <vector>

#include "extwrench/core/types.hpp"

namespace extwrench::sim {

/// One more sine per joint: amplitude_i sin(2π frequency_i t + phase_i) (each size n).
struct SineTerm {
  VectorX amplitude;
  VectorX frequency;
  VectorX phase;
};

/// q_d,i(t) = offset_i + amplitude_i sin(2π frequency_i t + phase_i) + Σ_more_sines, per joint
/// (all size n). Units: rad, rad, Hz, rad. With one sine per joint q̈_i = −ω² (q_i − offset_i)
/// follows q_i, and an inertia error looks like a gravity error; identification motions sum
/// several frequencies per joint (more_sines) so that calibration can tell them apart.
struct SinusoidalTrajectory {
  VectorX offset;
  VectorX amplitude;
  VectorX frequency;
  VectorX phase;
  std::vector<SineTerm> more_sines{};  ///< added to the first sine (none by default)

  /// Number of joints, or -1 when the vectors differ in size.
  [[nodiscard]] int size() const;
  /// Desired position, velocity and acceleration at t (outputs sized by the caller, size n).
  void evaluate(double t, Eigen::Ref<VectorX> q, Eigen::Ref<VectorX> dq,
                Eigen::Ref<VectorX> ddq) const noexcept;
};

}  // namespace extwrench::sim
