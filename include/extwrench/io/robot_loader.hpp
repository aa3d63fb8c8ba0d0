// Loading a robot description (URDF, DH YAML, or MJCF through the optional extwrench::mujoco)
// into a validated Model and its collision geometry. Throws extwrench::Error naming the file, line
// and field of any problem.
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
  /// MJCF only (docs/mujoco.md): the body that becomes link 0, for a file holding a scene;
  /// empty: the one top-level body whose subtree has joints.
  std::string root_body;
  /// MJCF only: keep just the bodies on the path root_body -> tip_body (one chain of a tree or
  /// a scene); empty: the root body's whole subtree.
  std::string tip_body;
};

/// Hands `options.locked_joints` to `builder` (used by every loader).
void lock_joints(const LoadOptions& options, ModelBuilder& builder);

/// A robot: its dynamics model, its collision geometry, and where it came from.
struct RobotDescription {
  Model model;
  GeometryModel geometry;
  std::filesystem::path source;
};

/// Reads an MJCF file into a RobotDescription (extwrench::mujoco's load_mjcf).
using MjcfLoader = RobotDescription (*)(const std::filesystem::path& path,
                                        const LoadOptions& options);
/// Installs the MJCF reader that load_robot uses for an .xml or .mjcf file whose root element is
/// <mujoco> (extwrench::mujoco's register_mjcf_loader() calls this; nullptr removes it). The io
/// library does not link MuJoCo: without a reader, such a file gets an error saying so.
void set_mjcf_loader(MjcfLoader loader) noexcept;

/// Loads a URDF (.urdf, .xml), a DH table (.yaml, .yml) or, when an MJCF reader is installed,
/// an MJCF file (.xml, .mjcf whose root element is <mujoco>), chosen by extension and root.
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
