#include "extwrench/sim/trajectory.hpp"

#include <cmath>
#include <numbers>

namespace extwrench::sim {

int SinusoidalTrajectory::size() const {
  const auto n = offset.size();
  if (amplitude.size() != n || frequency.size() != n || phase.size() != n) return -1;
  for (const SineTerm& s : more_sines)
    if (s.amplitude.size() != n || s.frequency.size() != n || s.phase.size() != n) return -1;
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
    for (const SineTerm& term : more_sines) {
      const double wk = 2.0 * std::numbers::pi * term.frequency[i];
      const double sk = std::sin(wk * t + term.phase[i]);
      const double ck = std::cos(wk * t + term.phase[i]);
      q[i] += term.amplitude[i] * sk;
      dq[i] += term.amplitude[i] * wk * ck;
      ddq[i] -= term.amplitude[i] * wk * wk * sk;
    }
  }
}

}  // namespace extwrench::sim
