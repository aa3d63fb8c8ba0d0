// Entry point of extwrench_bench: Google Benchmark's main plus context in the JSON output
// (robot source, compiler, flags), so that a bench.json says what it measured.
#include <benchmark/benchmark.h>

#include <exception>
#include <iostream>

#include "robots.hpp"

#ifndef EXTWRENCH_BENCH_FLAGS
#define EXTWRENCH_BENCH_FLAGS "unknown"
#endif

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  try {
    const auto& arm = extwrench::bench::paper_arm();  // loads and cross-checks both robots
    benchmark::AddCustomContext("robot", arm.source);
    if (const auto* panda = extwrench::bench::panda_arm(); panda != nullptr) {
      benchmark::AddCustomContext("mesh_robot", panda->source);
    }
    extwrench::bench::register_contact_benchmarks();
  } catch (const std::exception& e) {
    std::cerr << "extwrench_bench: set-up failed: " << e.what() << '\n';
    return 1;
  }
#if defined(__clang__)
  benchmark::AddCustomContext("compiler", "clang " __clang_version__);
#elif defined(__GNUC__)
  benchmark::AddCustomContext("compiler", "gcc " __VERSION__);
#endif
  benchmark::AddCustomContext("flags", EXTWRENCH_BENCH_FLAGS);
  // Debian builds libbenchmark without NDEBUG, and the library then prints a warning about its
  // own build below the context: say which build it means, next to the flags of ours.
  benchmark::AddCustomContext("timing_library",
                              "a '***WARNING*** Library was built as DEBUG' below is about "
                              "libbenchmark itself (Debian's package), not about the code "
                              "measured: that is built with the flags above");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
