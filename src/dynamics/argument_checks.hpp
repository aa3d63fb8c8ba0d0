// The arguments of the public dynamics functions checked against the model, as Pinocchio checks
// them: a q of the wrong size or a body index out of range would read and write past the end of
// the workspace's arrays. A few comparisons per call; the estimator validates its inputs before,
// so inside update() they never fire.
#pragma once

#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::detail {

[[noreturn]] inline void argument_error(const char* function, const std::string& what) {
  throw Error(std::string(function) + ": " + what);
}

/// `data` was made for a model with `model`'s bodies and joints (Data(model)).
inline void check_data(const char* function, const Model& model, const Data& data) {
  if (data.X_WB.size() != model.bodies.size() || data.tau.size() != model.nq()) [[unlikely]]
    argument_error(function, "data was made for another model (" +
                                 std::to_string(data.X_WB.size()) + " bodies, the model has " +
                                 std::to_string(model.bodies.size()) + ")");
}

/// A joint-space vector (q, dq, ddq, tau) of the model's n entries.
inline void check_joint_vector(const char* function, const char* name, Eigen::Index size,
                               const Model& model) {
  if (size != model.nq()) [[unlikely]]
    argument_error(function, std::string(name) + " has " + std::to_string(size) +
                                 " entries, the model has " + std::to_string(model.nq()) +
                                 " joints");
}

/// A body index of the model.
inline void check_body(const char* function, const char* name, int body, const Model& model) {
  if (body < 0 || body >= model.num_bodies()) [[unlikely]]
    argument_error(function, std::string(name) + " " + std::to_string(body) +
                                 " is not a body of the model (0.." +
                                 std::to_string(model.num_bodies() - 1) + ")");
}

}  // namespace extwrench::detail
