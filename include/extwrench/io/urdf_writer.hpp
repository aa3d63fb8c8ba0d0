// Writing a Model (and its collision geometry) back as URDF that load_urdf reads: used by
// `extwrench simulate` to hand the estimators' perturbed model to `extwrench estimate`.
#pragma once

#include <filesystem>
#include <string>

#include "extwrench/geometry/shapes.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

/// URDF text of `model`: one <link> per body (its merged mass properties as <inertial>, CoM
/// origin, inertia about the CoM in body axes), one <joint> per moving joint (placement,
/// axis, limits, <dynamics>), every extra named frame as a massless link on a fixed joint
/// (merged back into its body by the loader), and the collision shapes on their body (capsules
/// with the extwrench <capsule> extension, meshes by absolute file:// path and scale).
/// Numbers are written in the shortest form that reads back to the same double; rotations as
/// URDF rpy (exact to ~1e-16). Gravity is not part of URDF and is not written.
[[nodiscard]] std::string write_urdf_string(const Model& model, const GeometryModel& geometry);

/// Writes write_urdf_string to `path`. Throws extwrench::Error if the file cannot be written.
void write_urdf(const std::filesystem::path& path, const Model& model,
                const GeometryModel& geometry);

}  // namespace extwrench
