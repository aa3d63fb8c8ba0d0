// The fuzz bytes as a file, for the readers that take a path (they open what the tools open:
// docs/cli.md "Limits"). One file per process, rewritten for every input.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace extwrench_fuzz {

/// A private directory of this process under the system's temporary directory.
inline std::filesystem::path process_directory(const std::string& harness) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() /
                              ("extwrench_fuzz_" + harness + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

/// Writes the input to `path`; false when the file cannot be written (the input is skipped).
inline bool write_input(const std::filesystem::path& path, const std::uint8_t* data,
                        std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = size == 0 || std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

}  // namespace extwrench_fuzz
