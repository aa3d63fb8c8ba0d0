// The simulator's random generator is the core's platform-stable one (core/random.hpp).
#pragma once

#include "extwrench/core/random.hpp"

namespace extwrench::sim {

using Rng = extwrench::Rng;

}  // namespace extwrench::sim
