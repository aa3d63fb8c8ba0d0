// Desired joint trajectories for the closed-loop simulator.
#pragma once

#include "extwrench/core/types.hpp"

namespace extwrench::sim {

/// q_d,i(t) = offset_i + amplitude_i sin(2π frequency_i t + phase_i), per joint (all size n).
/// Units: rad, rad, Hz, rad.
struct SinusoidalTrajectory {
  VectorX offset;
  VectorX amplitude;
  VectorX frequency;
  VectorX phase;

  /// Number of joints, or -1 when the four vectors differ in size.
  [[nodiscard]] int size() const;
  /// Desired position, velocity and acceleration at t (outputs sized by the caller, size n).
  void evaluate(double t, Eigen::Ref<VectorX> q, Eigen::Ref<VectorX> dq,
                Eigen::Ref<VectorX> ddq) const noexcept;
};

}  // namespace extwrench::sim
