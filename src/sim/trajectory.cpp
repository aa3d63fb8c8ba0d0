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

namespace {

// a sin(2π f t + φ) and its first two time derivatives.
struct SineValue {
  double q, dq, ddq;
};
SineValue sine_at(double amplitude, double frequency, double phase, double t) noexcept {
  const double w = 2.0 * std::numbers::pi * frequency;
  const double s = std::sin(w * t + phase);
  const double c = std::cos(w * t + phase);
  return {amplitude * s, amplitude * w * c, -amplitude * w * w * s};
}

}  // namespace

void SinusoidalTrajectory::evaluate(double t, Eigen::Ref<VectorX> q, Eigen::Ref<VectorX> dq,
                                    Eigen::Ref<VectorX> ddq) const noexcept {
  for (Eigen::Index i = 0; i < offset.size(); ++i) {
    const SineValue first = sine_at(amplitude[i], frequency[i], phase[i], t);
    q[i] = offset[i] + first.q;
    dq[i] = first.dq;
    ddq[i] = first.ddq;
    for (const SineTerm& term : more_sines) {
      const SineValue more = sine_at(term.amplitude[i], term.frequency[i], term.phase[i], t);
      q[i] += more.q;
      dq[i] += more.dq;
      ddq[i] += more.ddq;
    }
  }
}

}  // namespace extwrench::sim
