// Loading a robot description (URDF or DH YAML) into a validated Model and its collision
// geometry. Throws extwrench::Error naming the file, line and field of any problem.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "extwrench/geometry/shapes.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

class ModelBuilder;

struct LoadOptions {
  /// Directories searched for `package://NAME/...`: NAME is looked up as a subdirectory of
  /// each. ROS_PACKAGE_PATH (colon-separated) is appended when `use_ros_package_path`.
  std::vector<std::filesystem::path> package_path;
  bool use_ros_package_path = true;
  bool load_meshes = true;         ///< false: mesh shapes are kept without triangles
  std::optional<Vector3> gravity;  ///< overrides the file's / default gravity
  /// Joints held at a value [rad | m] (joint name -> value): each becomes fixed there and its
  /// child link merges into the parent body (ModelBuilder::lock_joint), e.g. a gripper's
  /// fingers, which make a tree of an arm. Unknown or fixed joints, values outside the limits
  /// and non-finite values are errors.
  std::map<std::string, double> locked_joints;
  /// Where each lock was given, prefixing its errors ("--lock", "config.yaml:4:
  /// locked_joints.NAME"); a joint missing here is named "locked_joints".
  std::map<std::string, std::string> locked_joint_sources;
};

/// Hands `options.locked_joints` to `builder` (used by every loader).
void lock_joints(const LoadOptions& options, ModelBuilder& builder);

/// A robot: its dynamics model, its collision geometry, and where it came from.
struct RobotDescription {
  Model model;
  GeometryModel geometry;
  std::filesystem::path source;
};

/// Loads a URDF (.urdf, .xml) or a DH table (.yaml, .yml), chosen by extension.
[[nodiscard]] RobotDescription load_robot(const std::filesystem::path& path,
                                          const LoadOptions& options = {});
[[nodiscard]] RobotDescription load_urdf(const std::filesystem::path& path,
                                         const LoadOptions& options = {});
/// URDF from a string; `name` stands for the file name in error messages.
[[nodiscard]] RobotDescription load_urdf_string(const std::string& xml, const std::string& name,
                                                const LoadOptions& options = {});
[[nodiscard]] RobotDescription load_dh_yaml(const std::filesystem::path& path,
                                            const LoadOptions& options = {});

}  // namespace extwrench
