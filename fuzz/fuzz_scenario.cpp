// libFuzzer harness: any bytes as a simulation scenario (docs/simulation.md), written to a file
// scenarios/fuzz.yaml of a private directory whose models/ is the project's, so that the seed's
// `robot: ../models/paper_arm.urdf` loads the paper arm. Only an extwrench::Error may come out;
// every scheme of a scenario that loads must give an estimator configuration text.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <system_error>

#include "extwrench/core/error.hpp"
#include "extwrench/io/scenario_config.hpp"
#include "extwrench/sim/controller.hpp"
#include "extwrench/sim/sample_source.hpp"
#include "fuzz_input_file.hpp"

namespace {

std::filesystem::path scenario_path() {
  const std::filesystem::path dir = extwrench_fuzz::process_directory("scenario");
  std::error_code ec;
  std::filesystem::create_directories(dir / "scenarios", ec);
  std::filesystem::create_directory_symlink(EXTWRENCH_SOURCE_DIR "/models", dir / "models", ec);
  return dir / "scenarios" / "fuzz.yaml";
}

// Stands in for extwrench::mujoco's engine, which this harness does not link: with an engine
// registered, `engine: mujoco` is accepted and its `obstacles:` are parsed (never run here).
std::unique_ptr<extwrench::sim::SampleSource> no_engine(const extwrench::Scenario&,
                                                        extwrench::sim::ComputedTorqueController,
                                                        const extwrench::sim::SimulationConfig&) {
  return nullptr;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path path = scenario_path();
  extwrench::set_mujoco_engine(no_engine);
  if (!extwrench_fuzz::write_input(path, data, size)) return 0;
  extwrench::LoadOptions options;
  options.load_meshes = false;  // no file access from fuzzed mesh names
  options.use_ros_package_path = false;
  try {
    const extwrench::Scenario scenario = extwrench::load_scenario(path, options);
    for (const extwrench::SchemeSpec& scheme : scenario.schemes)
      (void)extwrench::scheme_config_yaml(scenario, scheme);
  } catch (const extwrench::Error&) {
  }
  return 0;
}
