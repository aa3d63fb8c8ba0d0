#include "extwrench/sim/trajectory.hpp"

#include <numbers>

namespace extwrench::sim {

int SinusoidalTrajectory::size() const {
  const auto n = offset.size();
  if (amplitude.size() != n || frequency.size() != n || phase.size() != n) return -1;
  return static_cast<int>(n);
}

void SinusoidalTrajectory::evaluate(double t, Eigen::Ref<VectorX> q, Eigen::Ref<VectorX> dq,
                                    Eigen::Ref<VectorX> ddq) const noexcept {
  for (Eigen::Index i = 0; i < offset.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * frequency[i];
    const double s = std::sin(w * t + phase[i]);
    const double c = std::cos(w * t + phase[i]);
    q[i] = offset[i] + amplitude[i] * s;
    dq[i] = amplitude[i] * w * c;
    ddq[i] = -amplitude[i] * w * w * s;
  }
}

}  // namespace extwrench::sim
