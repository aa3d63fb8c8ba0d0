// Checks of per-sample inputs shared by the observer and the estimators (real-time: noexcept,
// no allocation). Option checks, which may throw, live with their options.
#pragma once

#include <cmath>

#include "extwrench/core/status.hpp"
#include "extwrench/core/types.hpp"

namespace extwrench {

/// The largest magnitude a per-sample input may have: 1e9 (in SI units and radians no robot's q,
/// q̇, τ or base reading comes near it). A finite input beyond it, squared in the Coriolis terms
/// or integrated by the observer, overflows and leaves the state non-finite for good; it is
/// refused as kNonFinite.
inline constexpr double kLargestInput = 1e9;

/// Whether x is a usable input: finite and |x| <= kLargestInput (one comparison; NaN fails it).
[[nodiscard]] inline bool usable_input(double x) noexcept { return std::abs(x) <= kLargestInput; }

/// The largest magnitude of a time stamp: 1e12 s (31 700 years; a clock's epoch seconds, 1.8e9,
/// are far below). A finite time beyond it (DBL_MAX) made the step infinite and the residual
/// non-finite with status ok; it is refused as kNonFinite on the time channel.
inline constexpr double kLargestTime = 1e12;

/// Whether t is a usable time stamp: finite and |t| <= kLargestTime (NaN fails it).
[[nodiscard]] inline bool usable_time(double t) noexcept { return std::abs(t) <= kLargestTime; }

/// ok when v has n entries, all usable (usable_input); else kWrongSize (index = v's size) or
/// kNonFinite (index of the first bad entry) on `channel`.
[[nodiscard]] inline Status check_vector(const Eigen::Ref<const VectorX>& v, int n,
                                         Channel channel) noexcept {
  if (v.size() != n) return {StatusCode::kWrongSize, channel, static_cast<int>(v.size())};
  for (int i = 0; i < n; ++i) {
    if (!usable_input(v[i])) return {StatusCode::kNonFinite, channel, i};
  }
  return Status::success();
}

}  // namespace extwrench
