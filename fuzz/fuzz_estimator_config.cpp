// libFuzzer harness: any bytes as an estimator configuration (docs/config.md), read as if it were
// a file of tests/data/config, so that `robot: ../../../models/paper_arm.urdf` of the seeds loads
// the paper arm. Besides a configuration the only acceptable outcome is an extwrench::Error. A
// configuration that loads is then checked further: the estimator it configures is built (its
// options validated against the model), and its YAML form (to_yaml) reads back to the same form.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/estimator_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path name = EXTWRENCH_SOURCE_DIR "/tests/data/config/fuzz.yaml";
  extwrench::LoadOptions options;
  options.load_meshes = false;  // no file access from fuzzed mesh names
  options.use_ros_package_path = false;
  extwrench::EstimatorConfig config;
  try {
    config = extwrench::load_estimator_config_string(
        std::string(reinterpret_cast<const char*>(data), size), name, options);
  } catch (const extwrench::Error&) {
    return 0;
  }
  try {
    (void)extwrench::make_estimator(config);
  } catch (const extwrench::Error&) {
  }
  // to_yaml documents that loading its result gives the same options: its form is a fixed point.
  const std::string yaml = extwrench::to_yaml(config, name.parent_path());
  std::string again;
  try {
    again = extwrench::to_yaml(extwrench::load_estimator_config_string(yaml, name, options),
                               name.parent_path());
  } catch (const extwrench::Error& e) {
    std::fprintf(stderr, "fuzz_estimator_config: to_yaml's output is refused: %s\n%s\n", e.what(),
                 yaml.c_str());
    std::abort();
  }
  if (again != yaml) {
    std::fprintf(stderr, "fuzz_estimator_config: to_yaml round trip differs:\n%s\n---\n%s\n",
                 yaml.c_str(), again.c_str());
    std::abort();
  }
  return 0;
}
