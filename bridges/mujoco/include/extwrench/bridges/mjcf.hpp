// MJCF robots through MuJoCo's own compiler (docs/mujoco.md): a compiled mjModel becomes the
// project's validated Model and GeometryModel. Part of the optional extwrench::mujoco target;
// extwrench and extwrench::io never link MuJoCo.
#pragma once

#include <filesystem>
#include <string>

#include "extwrench/io/robot_loader.hpp"

struct mjModel_;  // <mujoco/mjmodel.h>; the header stays free of MuJoCo's

namespace extwrench::mujoco {

/// Compiles `path` with MuJoCo (mj_loadXML: includes, defaults, meshes, inertias as MuJoCo
/// simulates them) and converts it with robot_from_mjmodel. Throws extwrench::Error naming the
/// file and MuJoCo's element and line when MuJoCo rejects it, or the file and body/joint/geom
/// when the converted model fails the validation a URDF model gets.
[[nodiscard]] RobotDescription load_mjcf(const std::filesystem::path& path,
                                         const LoadOptions& options = {});

/// MJCF from a string (MuJoCo's virtual file system); `name` stands for the file in errors.
/// Files it names (meshes, includes) are looked up relative to the working directory.
[[nodiscard]] RobotDescription load_mjcf_string(const std::string& xml, const std::string& name,
                                                const LoadOptions& options = {});

/// The robot rooted at `options.root_body` (or the one top-level body with joints) of a
/// compiled model: its bodies (compiled mass, CoM, principal inertia), hinge and slide joints
/// (axis, anchor, reference, range, damping, frictionloss, armature), sites as frames, and
/// collision geoms (contype or conaffinity non-zero) as shapes. `file` prefixes every error.
[[nodiscard]] RobotDescription robot_from_mjmodel(const mjModel_* m, const std::string& file,
                                                  const LoadOptions& options = {});

/// Makes extwrench::load_robot read MJCF files through load_mjcf (set_mjcf_loader).
void register_mjcf_loader() noexcept;

}  // namespace extwrench::mujoco
