// Sample robots built in code (no file, no parser): the paper's arm and seeded random chains and
// trees, shared by the tests, the benchmarks and the examples.
#pragma once

#include <cstdint>

#include "extwrench/model/model.hpp"

namespace extwrench {

/// The paper's 7R arm (Table II, signs restored; standard DH with a_i = 0, θ_i = q_i), link 0
/// on the base sensor. Body i's frame sits at DH origin O_{i−1} with z along joint i's axis (it
/// is DH frame i−1 turned by q_i); frame "dh<i>" is DH frame i, attached to body i. There is no
/// "sensor" frame: the base sensor is at the world origin, 0.31 m below O_0 along z.
/// models/paper_arm.urdf describes the same robot.
[[nodiscard]] Model paper_arm();

struct RandomChainOptions {
  int n = 7;               ///< number of joints
  bool tree = false;       ///< random parents (a tree) instead of a serial chain
  bool prismatic = false;  ///< every third joint (i % 3 == 2) prismatic
  std::uint64_t seed = 1;  ///< the same seed gives the same model on every platform
};

/// A random but physically valid robot: masses in [0.5, 3] kg, CoMs within 0.1 m, principal
/// moments in [0.01, 0.05] kg m² in random axes, joint placements within 0.3 m and any rotation,
/// random unit axes; bodies "link<i>", joints "joint<i>".
[[nodiscard]] Model random_chain(const RandomChainOptions& options = {});

}  // namespace extwrench
