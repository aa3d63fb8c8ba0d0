// Dynamic parameters corrupted by bounded random errors (paper Sec. IV,
// docs/method.md#the-papers-experiment): what the controller and the estimators believe, while the
// simulated robot keeps the nominal ones.
#pragma once

#include <cstdint>

#include "extwrench/model/model.hpp"

namespace extwrench::sim {

/// Returns a copy of `model` with errors drawn from sim::Rng(seed), body by body (link 0
/// included), in a parametrisation that stays physically valid (docs/simulation.md "The perturbed
/// model"): the mass and each CoM coordinate multiplied by (1 + u); the rotational inertia
/// about the CoM as its principal second moments J_k (>= 0 <=> PSD and triangle inequality),
/// each multiplied by (1 + u), and its principal axes turned by an angle u [rad] about a random
/// axis; u uniform in [-fraction, +fraction]. A non-zero joint armature is multiplied by (1 + u)
/// too. Zero entries stay zero. Kinematics, other joint data and frames are unchanged.
/// fraction = 0.01 is the paper's ±1 %. Throws extwrench::Error if fraction is not in [0, 0.5).
[[nodiscard]] Model perturb_model(const Model& model, double fraction, std::uint64_t seed);

}  // namespace extwrench::sim
