// ContactDetector's release from the base sensor (docs/estimator.md#release-from-the-sensor):
// a release the residual confirms stays a release, even after a large push; a release the
// residual contradicts (the force is still there) is undone and not repeated.
#include <gtest/gtest.h>

#include <cmath>

#include "extwrench/estimation/detection.hpp"

namespace extwrench {
namespace {

constexpr int kJoints = 3;
constexpr double kDt = 0.001;      // [s]
constexpr double kGain = 100.0;    // observer gain K [1/s]: the residual decays as e^{-K t}
constexpr double kSettle = 0.05;   // 5 time constants, as the estimator passes
constexpr double kForceOff = 0.5;  // [s] when the sensor says the force is gone

/// What the detector sees over 1 s: a push from 0.1 s of residual `level` × τ_min on joint 2
/// and base force `level` × F_min. The sensor's instantaneous force drops to 0 at kForceOff;
/// the residual and the lagged base force decay from then on only if `force_ends`.
struct ReleaseRun {
  int declared_after_off = 0;  ///< samples with a declared contact after kForceOff + 20 ms
  int onsets = 0;              ///< rising edges of the declared contact
  double released_at = NAN;    ///< first release after kForceOff [s]
};

ReleaseRun run_detector(double level, bool force_ends) {
  DetectionOptions options;  // τ_min 1, F_min 5, ratio 0.5, min_duration 5 ms
  ContactDetector detector(options, kJoints, kSettle);
  ReleaseRun out;
  bool was = false;
  for (int k = 0; k <= 1000; ++k) {
    const double t = k * kDt;
    double size = t < 0.1 ? 0.0 : level;
    if (force_ends && t > kForceOff) size = level * std::exp(-kGain * (t - kForceOff));
    VectorX tau_ext = VectorX::Zero(kJoints);
    tau_ext[1] = size * options.tau_min[0];
    const double base_force = size * options.f_min;
    const double release_force = t < 0.1 ? NAN : (t > kForceOff ? 0.0 : base_force);
    const DetectionResult& det = detector.update(t, tau_ext, base_force, release_force);
    if (det.contact && !was) ++out.onsets;
    if (!det.contact && was && t > kForceOff && std::isnan(out.released_at)) out.released_at = t;
    if (det.contact && t > kForceOff + 0.02) ++out.declared_after_off;
    was = det.contact;
  }
  return out;
}

TEST(Detection, ASensorReleaseTheResidualConfirmsStaysReleased) {
  for (const double level : {3.0, 20.0, 200.0}) {  // 200: still over its threshold at 5 τ
    const ReleaseRun r = run_detector(level, true);
    EXPECT_EQ(r.onsets, 1) << level;
    EXPECT_NEAR(r.released_at, kForceOff + 0.005, 1.5e-3) << level;  // min_duration
    EXPECT_EQ(r.declared_after_off, 0) << level;
  }
}

TEST(Detection, ASensorReleaseTheResidualContradictsIsUndoneOnce) {
  // The sensor's force fell to 0 but the residual stays: the force is on another link than
  // the one the release assumed. The contact is declared again after the settle time and then
  // held (no release/onset cycles) while the residual lasts.
  const ReleaseRun r = run_detector(10.0, false);
  EXPECT_EQ(r.onsets, 2);
  EXPECT_NEAR(r.released_at, kForceOff + 0.005, 1.5e-3);
  const int samples_after = 1000 - static_cast<int>((kForceOff + 0.02) / kDt);
  // Re-declared at release + settle + min_duration, then held to the end.
  EXPECT_GE(r.declared_after_off, samples_after - static_cast<int>((kSettle + 0.012) / kDt));
}

}  // namespace
}  // namespace extwrench
