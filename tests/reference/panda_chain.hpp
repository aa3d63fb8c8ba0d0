// The shared Panda (../shared/models, collision meshes) as a 7-joint chain for the reference
// tests: the finger joints become fixed (merged into the hand), mesh paths made absolute so the
// string loads from anywhere. Tests skip when panda_urdf() does not exist.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "extwrench/io/robot_loader.hpp"

namespace extwrench::test {

inline std::filesystem::path panda_urdf() {
  return std::filesystem::path(EXTWRENCH_SHARED_DIR) /
         "models/franka_panda/urdf_example-robot-data/urdf/panda.relative.urdf";
}

/// Replaces every occurrence of `from` (plain text; <regex> trips a false GCC 12 warning at -O1).
inline std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

/// Removes every self-closing element `<tag .../>`.
inline std::string remove_elements(std::string text, const std::string& tag) {
  for (std::size_t at = text.find("<" + tag); at != std::string::npos;
       at = text.find("<" + tag, at)) {
    text.erase(at, text.find("/>", at) + 2 - at);
  }
  return text;
}

inline RobotDescription panda_chain() {
  const std::filesystem::path urdf = panda_urdf();
  std::ifstream in(urdf);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string xml = ss.str();
  xml = remove_elements(xml, "mimic");
  xml = replace_all(xml, R"(type="prismatic")", R"(type="fixed")");
  xml = replace_all(xml, R"(filename="../)", "filename=\"" + urdf.parent_path().string() + "/../");
  return load_urdf_string(xml, urdf.string());
}

}  // namespace extwrench::test
