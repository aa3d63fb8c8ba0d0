// Reading and writing whole text files, and running the CLI with both streams captured: what
// the system and app tests share.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace extwrench::test {

/// One CSV line split at every comma (the tests' own splitting: the logs and estimates the
/// tools write have no quoted cells); a trailing comma gives a trailing empty cell.
inline std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream cs(line);
  std::string cell;
  while (std::getline(cs, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

/// The CSV text with the columns whose names start with any of `prefixes` removed.
inline std::string drop_columns(const std::string& csv, const std::vector<std::string>& prefixes) {
  std::istringstream in(csv);
  std::string line, out;
  std::vector<bool> keep;
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split_cells(line);
    if (keep.empty()) {
      for (const auto& c : cells) {
        bool k = true;
        for (const auto& p : prefixes) k = k && c.rfind(p, 0) != 0;
        keep.push_back(k);
      }
    }
    std::string row;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (i < keep.size() && keep[i]) row += (row.empty() ? "" : ",") + cells[i];
    }
    out += row + "\n";
  }
  return out;
}

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
