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

namespace {

// The text without its "  pose: {...}" line (the sensor pose, compared numerically).
std::string without_pose_line(const std::string& text) {
  const std::size_t at = text.find("\n  pose: {");
  if (at == std::string::npos) return text;
  const std::size_t end = text.find('\n', at + 1);
  return text.substr(0, at) + (end == std::string::npos ? std::string() : text.substr(end));
}

}  // namespace

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
  // The sensor rotation is written as roll, pitch, yaw, which no double round trip keeps to the
  // last digit for a general rotation: its line is compared as a pose, to 1e-12.
  const std::string yaml = extwrench::to_yaml(config, name.parent_path());
  std::string again;
  extwrench::EstimatorConfig reread;
  try {
    reread = extwrench::load_estimator_config_string(yaml, name, options);
    again = extwrench::to_yaml(reread, name.parent_path());
  } catch (const extwrench::Error& e) {
    std::fprintf(stderr, "fuzz_estimator_config: to_yaml's output is refused: %s\n%s\n", e.what(),
                 yaml.c_str());
    std::abort();
  }
  if (!reread.options.sensor.X_WS.is_approx(config.options.sensor.X_WS, 1e-12)) {
    std::fprintf(stderr, "fuzz_estimator_config: the sensor pose does not read back:\n%s\n",
                 yaml.c_str());
    std::abort();
  }
  if (without_pose_line(again) != without_pose_line(yaml)) {
    std::fprintf(stderr, "fuzz_estimator_config: to_yaml round trip differs:\n%s\n---\n%s\n",
                 yaml.c_str(), again.c_str());
    std::abort();
  }
  return 0;
}
