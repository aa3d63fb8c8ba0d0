// load_robot: picks the URDF or the DH-YAML loader by file extension.
#include "extwrench/io/robot_loader.hpp"

#include <algorithm>
#include <cctype>

#include "extwrench/core/error.hpp"

namespace extwrench {

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
