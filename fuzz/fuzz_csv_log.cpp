// libFuzzer harness: any bytes as a robot log of the paper arm, read to the end through
// LogReader (the CSV dialect, the log columns, number rules, time checks). Only
// extwrench::Error may come out. The input goes through a file, as LogReader reads files.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/model/sample_models.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const extwrench::Model model = extwrench::paper_arm();
  static const std::string path = "/tmp/extwrench_fuzz_log_" + std::to_string(::getpid()) + ".csv";
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size > 0) (void)std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    return 0;
  }
  try {
    extwrench::LogReader reader(path, model);
    extwrench::Sample sample;
    while (reader.next(sample)) {
    }
  } catch (const extwrench::Error&) {
  }
  return 0;
}
