// The friction mapping shared by estimator configurations and calibration files
// {sign, viscous, coulomb, offset, smoothing_velocity, velocity_shift}. Private to src/io.
#pragma once

#include <string>

#include "extwrench/observer/friction.hpp"
#include "yaml_reader.hpp"

namespace extwrench::io_detail {

/// Reads the mapping at `node` (key `key` in messages) for n joints.
[[nodiscard]] JointFriction read_friction_mapping(const YamlReader& rd, const YAML::Node& node,
                                                  int n, const std::string& key);

/// The mapping as one YAML flow line "{viscous: ..., ...}" (round-trip precision).
[[nodiscard]] std::string friction_mapping_yaml(const JointFriction& friction);

/// A list "[a, b, ...]", or the single value when all entries are equal (round-trip precision).
[[nodiscard]] std::string yaml_list(const VectorX& v);

}  // namespace extwrench::io_detail
