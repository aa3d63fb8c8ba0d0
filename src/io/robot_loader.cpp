// load_robot: picks the URDF, DH-YAML or MJCF loader by file extension and root element.
#include "extwrench/io/robot_loader.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstring>

#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/model/model_builder.hpp"

namespace extwrench {

namespace {

std::atomic<MjcfLoader> g_mjcf_loader{nullptr};

// True when the file parses as XML with root <mujoco>; a malformed file is left to the URDF
// parser, whose messages name the line.
bool is_mjcf(const std::filesystem::path& path) {
  const std::string text = read_input_file(path, "robot");
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS) return false;
  const tinyxml2::XMLElement* root = doc.RootElement();
  return root != nullptr && std::strcmp(root->Name(), "mujoco") == 0;
}

// The MJCF-only options, refused for the other formats rather than silently ignored.
void check_mjcf_only_options(const std::filesystem::path& path, const LoadOptions& options) {
  if (!options.root_body.empty() || !options.tip_body.empty()) {
    throw Error(path.string() + ": a root or tip body ('" + options.root_body + "', '" +
                options.tip_body +
                "') chooses the chain in an MJCF scene (--root-body, --tip-body; root_body, "
                "tip_body in a configuration); a URDF or DH table describes one robot already: "
                "leave them out");
  }
}

}  // namespace

void set_mjcf_loader(MjcfLoader loader) noexcept { g_mjcf_loader.store(loader); }

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
  if (ext == ".xml" || ext == ".mjcf") {
    const MjcfLoader mjcf = g_mjcf_loader.load();
    if (mjcf != nullptr && is_mjcf(path)) return mjcf(path, options);
  }
  if (ext == ".urdf" || ext == ".xml" || ext == ".mjcf") {
    check_mjcf_only_options(path, options);
    return load_urdf(path, options);
  }
  if (ext == ".yaml" || ext == ".yml") {
    check_mjcf_only_options(path, options);
    return load_dh_yaml(path, options);
  }
  throw Error(
      path.string() + ": unknown robot file type '" + ext +
      "' (expected .urdf or .xml for URDF, .yaml or .yml for a DH table, .xml or .mjcf for MJCF)" +
      (ext == ".xacro" ? std::string("; a xacro file must be expanded into a URDF first (ROS's "
                                     "xacro: `xacro robot.urdf.xacro > robot.urdf`)")
                       : std::string()));
}

}  // namespace extwrench
