// Deterministic, seeded random states for tests (never time-seeded: no flaky tests), from the
// core's platform-stable generator: the standard distributions are implementation-defined, so
// the same seed would give other states with another standard library.
#pragma once

#include <algorithm>
#include <cstdint>

#include "extwrench/core/random.hpp"
#include "extwrench/core/types.hpp"

namespace extwrench::test {

class SeededRng {
 public:
  explicit SeededRng(std::uint64_t seed) : engine_(seed) {}
  double uniform(double lo, double hi) { return engine_.uniform(lo, hi); }
  VectorX uniform_vector(int n, double lo, double hi) {
    VectorX v(n);
    for (int i = 0; i < n; ++i) v[i] = uniform(lo, hi);
    return v;
  }
  Vector3 uniform_vector3(double lo, double hi) {
    return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
  }
  /// Standard normal.
  double normal() { return engine_.normal(); }
  /// 64 random bits.
  std::uint64_t bits() { return engine_.next(); }

 private:
  Rng engine_;
};

/// Relative comparison with an absolute floor: |a - b| <= tol * max(1, |b|) element-wise max.
inline double relative_error(const MatrixX& a, const MatrixX& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace extwrench::test
