// Status of a real-time call: returned by value, never thrown.
#pragma once

#include <cstdint>
#include <string_view>

namespace extwrench {

/// Outcome of a real-time update. Ok and the informational codes leave valid outputs; the
/// error codes leave the object's state unchanged and the outputs in a defined state (NaN).
enum class StatusCode : std::uint8_t {
  kOk = 0,
  // Input errors: nothing was changed.
  kWrongSize,  ///< an input vector has the wrong size
  kNonFinite,  ///< NaN or Inf in an input, a magnitude above kLargestInput (1e9), a time above 1e12
               ///< s
  kNonIncreasingTime,  ///< the time stamp did not increase
  kNotInitialized,     ///< reset() was not called
  // Numerical outcomes.
  kSingular,  ///< a matrix could not be factored
};

/// Which input channel a Status refers to (for kWrongSize / kNonFinite).
enum class Channel : std::uint8_t {
  kNone,
  kTime,
  kPosition,
  kVelocity,
  kTorque,
  kAcceleration,
  kBaseWrench
};

struct Status {
  StatusCode code = StatusCode::kOk;
  Channel channel = Channel::kNone;
  /// kNonFinite: the element of the channel; kWrongSize: the size received (the expected one is
  /// the robot's n; 0 on base_wrench: the configured sensor's reading is missing; set_payload:
  /// the body index given); kNonIncreasingTime: 0; otherwise -1.
  int index = -1;

  [[nodiscard]] constexpr bool ok() const noexcept { return code == StatusCode::kOk; }
  static constexpr Status success() noexcept { return {}; }
};

constexpr std::string_view to_string(StatusCode c) noexcept {
  switch (c) {
    case StatusCode::kOk:
      return "ok";
    case StatusCode::kWrongSize:
      return "wrong_size";
    case StatusCode::kNonFinite:
      return "non_finite";
    case StatusCode::kNonIncreasingTime:
      return "non_increasing_time";
    case StatusCode::kNotInitialized:
      return "not_initialized";
    case StatusCode::kSingular:
      return "singular";
  }
  return "unknown";
}

constexpr std::string_view to_string(Channel c) noexcept {
  switch (c) {
    case Channel::kNone:
      return "none";
    case Channel::kTime:
      return "t";
    case Channel::kPosition:
      return "q";
    case Channel::kVelocity:
      return "dq";
    case Channel::kTorque:
      return "tau";
    case Channel::kAcceleration:
      return "ddq";
    case Channel::kBaseWrench:
      return "base_wrench";
  }
  return "unknown";
}

}  // namespace extwrench
