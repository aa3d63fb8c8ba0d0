// Reading and writing whole text files, and running the CLI with both streams captured: what
// the system and app tests share.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace extwrench::test {

/// The file's bytes; empty when it cannot be read.
inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

struct CliResult {
  int code = -1;  ///< exit code, or 128 + signal
  std::string out;
  std::string err;
};

/// Runs `ENV 'BINARY' ARGS` through /bin/sh (ARGS already shell-quoted) with stdin from
/// `stdin_file`; stdout and stderr go through files in `dir`.
inline CliResult run_cli(const std::string& binary, const std::string& args,
                         const std::filesystem::path& dir,
                         const std::string& stdin_file = "/dev/null", const std::string& env = "") {
  const std::filesystem::path out = dir / "stdout.txt";
  const std::filesystem::path err = dir / "stderr.txt";
  const std::string command = env + " '" + binary + "' " + args + " >'" + out.string() + "' 2>'" +
                              err.string() + "' <'" + stdin_file + "'";
  const int status = std::system(command.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

}  // namespace extwrench::test
