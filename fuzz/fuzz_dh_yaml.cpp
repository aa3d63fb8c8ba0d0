// libFuzzer harness: any bytes as a DH-table robot (YAML, docs/model.md). The only acceptable
// outcome besides a model is an extwrench::Error (a crash, a sanitizer report, a timeout or any
// other exception is a finding). The input goes through a file, as load_dh_yaml reads files.
#include <cstddef>
#include <cstdint>

#include "extwrench/core/error.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "fuzz_input_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path path =
      extwrench_fuzz::process_directory("dh_yaml") / "robot.yaml";
  if (!extwrench_fuzz::write_input(path, data, size)) return 0;
  extwrench::LoadOptions options;
  options.load_meshes = false;  // no file access from fuzzed names
  options.use_ros_package_path = false;
  try {
    (void)extwrench::load_dh_yaml(path, options);
  } catch (const extwrench::Error&) {
  }
  return 0;
}
