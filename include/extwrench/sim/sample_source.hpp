// A closed-loop simulation seen as a stream of log rows: what `extwrench simulate` writes.
// sim::Simulator (the rigid-body RK4 engine) is one; the MuJoCo engine of extwrench::mujoco
// (bridges/mujoco, `engine: mujoco` in a scenario) is another.
#pragma once

#include "extwrench/core/sample.hpp"

namespace extwrench::sim {

class SampleSource {
 public:
  SampleSource() = default;
  SampleSource(const SampleSource&) = default;
  SampleSource& operator=(const SampleSource&) = default;
  virtual ~SampleSource() = default;

  /// Number of samples the run produces.
  [[nodiscard]] virtual long num_samples() const = 0;
  /// Fills `out` with the next sample (measurements, the torque commanded and the truth at t_k),
  /// then advances to t_{k+1}. Returns false when the run is over. Throws extwrench::Error when
  /// the simulation fails (diverges).
  virtual bool next(Sample& out) = 0;
};

}  // namespace extwrench::sim
