#include "extwrench/app/gnuplot.hpp"

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "extwrench/core/error.hpp"
#include "extwrench/io/csv.hpp"

namespace extwrench {

Decimator::Decimator(int width, int max_points) : width_(width), max_points_(max_points) {
  data_.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(2 * max_points + 2));
}

void Decimator::push(const double* values) {
  if (index_++ % stride_ != 0) return;
  data_.insert(data_.end(), values, values + width_);
  if (rows() >= 2 * max_points_) {
    // Keep rows 0, 2, 4, ...: they are the multiples of the doubled stride.
    const int n = rows();
    int kept = 0;
    for (int i = 0; i < n; i += 2, ++kept) {
      std::copy(row(i), row(i) + width_,
                data_.begin() + static_cast<std::ptrdiff_t>(kept) * width_);
    }
    data_.resize(static_cast<std::size_t>(kept) * width_);
    stride_ *= 2;
    // The next accepted index must be a multiple of the new stride.
  }
}

void Decimator::write(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw Error(path.string() + ": cannot create the file");
  std::string line;
  for (int i = 0; i < rows(); ++i) {
    line.clear();
    for (int k = 0; k < width_; ++k) {
      if (k) line += ' ';
      const double v = row(i)[k];
      if (std::isnan(v)) {
        line += "NaN";
      } else {
        CsvWriter::append(line, v);
      }
    }
    line += '\n';
    out << line;
  }
  if (!out) throw Error(path.string() + ": write failed");
}

bool gnuplot_available() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

std::string gnuplot_quote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) {
    out += c;
    if (c == '\'') out += '\'';
  }
  return out + "'";
}

void run_gnuplot(const std::filesystem::path& script) {
  if (!gnuplot_available()) {
    throw Error(
        "gnuplot not found on the PATH: figures need it (Debian: sudo apt-get install "
        "gnuplot-nox); or pass --no-figures");
  }
  const std::filesystem::path dir = script.parent_path().empty() ? "." : script.parent_path();
  const std::string command = "cd " + gnuplot_quote(dir.string()) + " && gnuplot " +
                              gnuplot_quote(script.filename().string()) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw Error("cannot run gnuplot for " + script.string());
  std::string output;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = pclose(pipe);
  if (status != 0 || output.find("rror") != std::string::npos) {
    throw Error("gnuplot failed on " + script.string() + ":\n" + output);
  }
}

std::string gnuplot_png_preamble(const std::filesystem::path& png, int width, int height) {
  std::ostringstream s;
  s << "set terminal pngcairo size " << width << "," << height
    << " enhanced font 'DejaVu Sans,11'\n"
    << "set output " << gnuplot_quote(png.filename().string()) << "\n"
    << "set grid\nset key outside right top\nset datafile missing 'NaN'\n";
  return s.str();
}

}  // namespace extwrench
