// libFuzzer harness: any bytes as an MJCF, through MuJoCo's compiler and our conversion
// (bridges/mujoco). The only acceptable outcome besides a model is an extwrench::Error. MuJoCo
// itself is not instrumented (Debian's library): coverage guides the fuzzer through our code.
#include <cstddef>
#include <cstdint>
#include <string>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  extwrench::LoadOptions options;
  options.load_meshes = false;
  try {
    (void)extwrench::mujoco::load_mjcf_string(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.xml", options);
  } catch (const extwrench::Error&) {
  }
  return 0;
}
