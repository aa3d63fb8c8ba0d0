// Deterministic, seeded random states for tests (never time-seeded: no flaky tests).
#pragma once

#include <random>

#include "extwrench/core/types.hpp"

namespace extwrench::test {

class SeededRng {
 public:
  explicit SeededRng(unsigned seed) : engine_(seed) {}
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(engine_);
  }
  VectorX uniform_vector(int n, double lo, double hi) {
    VectorX v(n);
    for (int i = 0; i < n; ++i) v[i] = uniform(lo, hi);
    return v;
  }
  Vector3 uniform_vector3(double lo, double hi) {
    return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
  }
  std::mt19937& engine() { return engine_; }

 private:
  std::mt19937 engine_;
};

/// Relative comparison with an absolute floor: |a - b| <= tol * max(1, |b|) element-wise max.
inline double relative_error(const MatrixX& a, const MatrixX& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace extwrench::test
