// Private helpers shared by the URDF and DH-YAML loaders: white-space splitting, mesh path
// resolution, and turning per-link collision declarations into a GeometryModel.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "extwrench/geometry/shapes.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::io_detail {

/// Splits on white space.
std::vector<std::string_view> split_ws(std::string_view text);

/// A collision shape as declared on a link (or a frame): `shape.placement` is X_{frame, shape},
/// body not yet known. `mesh_uri` is the file name as written (kMesh only).
struct ShapeSpec {
  CollisionShape shape;
  std::string frame;  ///< link (or frame) the shape is declared in
  std::string mesh_uri;
  std::string source;  ///< "file:line: <mesh> of link 'x'", prefix of error messages
};

/// Resolves a mesh file name: `package://NAME/rest` through options.package_path then
/// ROS_PACKAGE_PATH (each directory holding NAME/rest, or rest, or a trailing part of rest of
/// at least two components; docs/model.md "Meshes"), `file:///abs`, or a path relative to
/// `base_dir`. Returns nothing when the file cannot be found; `why` then says why.
std::optional<std::filesystem::path> resolve_mesh_path(const std::string& uri,
                                                       const std::filesystem::path& base_dir,
                                                       const LoadOptions& options,
                                                       std::string* why);

/// Places every shape on its body (X_{body, shape} = X_{body, frame} * X_{frame, shape}) and,
/// when options.load_meshes, loads the meshes. Throws extwrench::Error prefixed by the shape's
/// source when a mesh cannot be resolved or loaded.
GeometryModel build_geometry(const Model& model, const std::vector<ShapeSpec>& shapes,
                             const std::filesystem::path& base_dir, const LoadOptions& options);

}  // namespace extwrench::io_detail
