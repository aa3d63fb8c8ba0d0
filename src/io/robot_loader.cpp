// load_robot: picks the URDF or the DH-YAML loader by file extension.
#include "extwrench/io/robot_loader.hpp"

#include <algorithm>
#include <cctype>

#include "extwrench/core/error.hpp"
#include "extwrench/model/model_builder.hpp"

namespace extwrench {

void lock_joints(const LoadOptions& options, ModelBuilder& builder) {
  for (const auto& [name, value] : options.locked_joints) {
    const auto source = options.locked_joint_sources.find(name);
    builder.lock_joint(
        name, value,
        source == options.locked_joint_sources.end() ? "locked_joints" : source->second);
  }
}

RobotDescription load_robot(const std::filesystem::path& path, const LoadOptions& options) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".urdf" || ext == ".xml") return load_urdf(path, options);
  if (ext == ".yaml" || ext == ".yml") return load_dh_yaml(path, options);
  throw Error(path.string() + ": unknown robot file type '" + ext +
              "' (expected .urdf or .xml for URDF, .yaml or .yml for a DH table)");
}

}  // namespace extwrench
