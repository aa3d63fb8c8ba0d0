// Dynamic parameters corrupted by bounded random errors (paper Sec. IV,
// docs/method.md#the-papers-experiment): what the controller and the estimators believe, while the
// simulated robot keeps the nominal ones.
#pragma once

#include <cstdint>

#include "extwrench/model/model.hpp"

namespace extwrench::sim {

/// Returns a copy of `model` whose every body (link 0 included) has its mass, its CoM
/// coordinates and its six inertia entries (about the CoM, body axes: xx, xy, xz, yy, yz, zz)
/// each multiplied by (1 + u), u uniform in [-fraction, +fraction], drawn independently in that
/// order, body by body, from sim::Rng(seed). Zero entries stay zero; the tensor stays symmetric.
/// Kinematics, joint data and frames are unchanged. fraction = 0.01 is the paper's ±1 %.
/// Throws extwrench::Error if fraction is not in [0, 0.5) (larger errors can make a body's
/// inertia non-physical).
[[nodiscard]] Model perturb_model(const Model& model, double fraction, std::uint64_t seed);

}  // namespace extwrench::sim
