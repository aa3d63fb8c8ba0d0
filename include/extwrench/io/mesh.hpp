// Triangle meshes from files (assimp) with an Embree line-query structure attached.
#pragma once

#include <filesystem>
#include <memory>

#include "extwrench/geometry/shapes.hpp"

namespace extwrench {

/// Loads every triangle of a mesh file (STL, OBJ, DAE, ... anything assimp reads), applies
/// `scale`, and builds its ray caster. Throws extwrench::Error naming the file.
[[nodiscard]] std::shared_ptr<const TriangleMesh> load_mesh(const std::filesystem::path& path,
                                                            const Vector3& scale = Vector3::Ones());

}  // namespace extwrench
