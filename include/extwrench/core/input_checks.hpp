// Checks of per-sample inputs shared by the observer and the estimators (real-time: noexcept,
// no allocation). Option checks, which may throw, live with their options.
#pragma once

#include <cmath>

#include "extwrench/core/status.hpp"
#include "extwrench/core/types.hpp"

namespace extwrench {

/// ok when v has n entries, all finite; else kWrongSize (index = v's size) or kNonFinite (index
/// of the first bad entry) on `channel`.
[[nodiscard]] inline Status check_vector(const Eigen::Ref<const VectorX>& v, int n,
                                         Channel channel) noexcept {
  if (v.size() != n) return {StatusCode::kWrongSize, channel, static_cast<int>(v.size())};
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return {StatusCode::kNonFinite, channel, i};
  }
  return Status::success();
}

}  // namespace extwrench
