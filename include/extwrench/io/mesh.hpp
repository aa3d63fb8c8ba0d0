// Triangle meshes from files (assimp) with an Embree line-query structure attached.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>

#include "extwrench/geometry/mesh_ray_caster.hpp"
#include "extwrench/geometry/shapes.hpp"

namespace extwrench {

/// Most triangles a mesh may have (docs/model.md "Limits").
inline constexpr std::size_t kMaxMeshTriangles = 20'000'000;

/// Loads every triangle of a mesh file (STL, OBJ, DAE, ... anything assimp reads): all meshes
/// of the scene merged, node transforms applied, identical vertices joined, polygons
/// triangulated, then `scale` applied per axis (URDF <mesh scale>), and builds its Embree ray
/// caster. Collada files are read in their own coordinates (their up axis is ignored, as URDF
/// tools do). Throws extwrench::Error naming the file if assimp fails or there is no triangle.
[[nodiscard]] std::shared_ptr<const TriangleMesh> load_mesh(const std::filesystem::path& path,
                                                            const Vector3& scale = Vector3::Ones());

/// A TriangleMesh from vertices (3×V, mesh frame) and triangles (3×T vertex indices,
/// counter-clockwise seen from outside), with an Embree ray caster. `name` is stored as the
/// mesh's path and names it in errors. Throws extwrench::Error if an index is out of range, a
/// coordinate is not finite or there is no triangle.
[[nodiscard]] std::shared_ptr<const TriangleMesh> make_triangle_mesh(
    Matrix3X vertices, Eigen::Matrix<int, 3, Eigen::Dynamic> triangles, const std::string& name);

/// An Embree 3 ray caster over these triangles (single precision, robust/watertight mode; one
/// traversal reports every crossed triangle through an intersection filter). Thread-safe,
/// allocation-free queries. Throws extwrench::Error (naming `name`) if Embree fails.
[[nodiscard]] std::shared_ptr<const MeshRayCaster> make_embree_ray_caster(
    const Matrix3X& vertices, const Eigen::Matrix<int, 3, Eigen::Dynamic>& triangles,
    const std::string& name);

}  // namespace extwrench
