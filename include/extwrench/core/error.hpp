// Errors of the set-up tier (building, parsing, configuration). The control loop never throws:
// it returns a Status (core/status.hpp).
#pragma once

#include <stdexcept>
#include <string>

namespace extwrench {

/// The one exception type of the library. Its message names where the problem is (file, line or
/// element, field) and what was expected, e.g.
///   "robot.urdf:42: <inertia> of link 'link3': ixx: expected a number, got 'abc'".
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace extwrench
