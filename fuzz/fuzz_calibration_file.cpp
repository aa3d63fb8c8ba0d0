// libFuzzer harness: any bytes as a calibration file (CALIB.yaml, docs/calibration.md), included
// by an estimator configuration of the paper arm (`calibration: calib.yaml`), once with a base
// F/T sensor and once without. Besides a configuration the only acceptable outcome is an
// extwrench::Error. A calibration that loads is then checked further: the estimator the
// configuration builds is made (its merged options validated against the model), and the file
// `calibrate` would write for it (calibration_to_yaml) reads back to the same text.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/calibration_file.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "fuzz_input_file.hpp"

namespace {

constexpr int kJoints = 7;  // the paper arm's

void check_round_trip(const std::filesystem::path& dir, const extwrench::Calibration& loaded) {
  const std::string text = extwrench::calibration_to_yaml(loaded, nullptr);
  const std::filesystem::path again_path = dir / "again.yaml";
  if (!extwrench_fuzz::write_input(again_path, reinterpret_cast<const std::uint8_t*>(text.data()),
                                   text.size()))
    return;
  std::string again;
  try {
    again =
        extwrench::calibration_to_yaml(extwrench::load_calibration(again_path, kJoints), nullptr);
  } catch (const extwrench::Error& e) {
    std::fprintf(stderr, "fuzz_calibration_file: calibration_to_yaml's output is refused: %s\n%s\n",
                 e.what(), text.c_str());
    std::abort();
  }
  if (again != text) {
    std::fprintf(stderr, "fuzz_calibration_file: the round trip differs:\n%s\n---\n%s\n",
                 text.c_str(), again.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path dir = extwrench_fuzz::process_directory("calibration_file");
  if (!extwrench_fuzz::write_input(dir / "calib.yaml", data, size)) return 0;
  extwrench::LoadOptions options;
  options.load_meshes = false;
  options.use_ros_package_path = false;
  const std::string robot = "robot: " EXTWRENCH_SOURCE_DIR "/models/paper_arm.urdf\n";
  for (const char* sensor : {"ft", "none"}) {
    const std::string config =
        robot + "sensor: {type: " + sensor + "}\nobserver: {gain: 100}\ncalibration: calib.yaml\n";
    try {
      const extwrench::EstimatorConfig loaded =
          extwrench::load_estimator_config_string(config, dir / "config.yaml", options);
      (void)extwrench::make_estimator(loaded);
    } catch (const extwrench::Error&) {
    }
  }
  extwrench::Calibration calibration;
  try {
    calibration = extwrench::load_calibration(dir / "calib.yaml", kJoints);
  } catch (const extwrench::Error&) {
    return 0;
  }
  check_round_trip(dir, calibration);
  return 0;
}
