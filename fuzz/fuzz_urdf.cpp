// libFuzzer harness: any bytes as a URDF. The only acceptable outcome besides a model is an
// extwrench::Error (a crash, a sanitizer report or any other exception is a finding).
#include <cstddef>
#include <cstdint>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/robot_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  extwrench::LoadOptions options;
  options.load_meshes = false;  // no file access from fuzzed names
  options.use_ros_package_path = false;
  try {
    (void)extwrench::load_urdf_string(std::string(reinterpret_cast<const char*>(data), size),
                                      "fuzz.urdf", options);
  } catch (const extwrench::Error&) {
  }
  return 0;
}
