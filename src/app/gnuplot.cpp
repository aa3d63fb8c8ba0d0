#include "extwrench/app/gnuplot.hpp"

#include <sys/wait.h>

#include <algorithm>
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

namespace {

// The envelope of two values, NaN meaning "no value".
double lower(double a, double b) { return std::isnan(a) || b < a ? b : a; }
double upper(double a, double b) { return std::isnan(a) || b > a ? b : a; }

// A word for /bin/sh: single-quoted, each ' as '\''.
std::string shell_quote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

void write_row(std::ofstream& out, std::string& line, const double* row, int width) {
  line.clear();
  for (int k = 0; k < width; ++k) {
    if (k) line += ' ';
    if (std::isnan(row[k])) {
      line += "NaN";
    } else {
      CsvWriter::append(line, row[k]);
    }
  }
  line += '\n';
  out << line;
}

}  // namespace

EnvelopeDecimator::EnvelopeDecimator(int width, int max_points)
    : width_(width),
      max_points_(std::max(max_points, 2)),
      open_(2 * static_cast<std::size_t>(width)) {
  data_.reserve(2 * static_cast<std::size_t>(width) * static_cast<std::size_t>(max_points_ + 1));
}

void EnvelopeDecimator::push(const double* v) {
  double* lo = open_.data();
  double* hi = lo + width_;
  if (in_bucket_ == 0) {
    std::copy(v, v + width_, lo);
    std::copy(v, v + width_, hi);
  } else {
    hi[0] = v[0];  // the bucket's last time
    for (int k = 1; k < width_; ++k) {
      lo[k] = lower(lo[k], v[k]);
      hi[k] = upper(hi[k], v[k]);
    }
  }
  if (++in_bucket_ == stride_) close_bucket();
}

void EnvelopeDecimator::close_bucket() {
  data_.insert(data_.end(), open_.begin(), open_.end());
  in_bucket_ = 0;
  const std::size_t bucket = 2 * static_cast<std::size_t>(width_);
  if (data_.size() / bucket >= static_cast<std::size_t>(max_points_)) merge_pairs();
}

void EnvelopeDecimator::merge_pairs() {
  const auto w = static_cast<std::size_t>(width_);
  const std::size_t buckets = data_.size() / (2 * w);
  std::size_t kept = 0;
  for (std::size_t b = 0; b < buckets; b += 2, ++kept) {
    double* to = data_.data() + kept * 2 * w;
    const double* a = data_.data() + b * 2 * w;
    std::copy(a, a + 2 * w, to);     // to may alias a (kept <= b)
    if (b + 1 == buckets) continue;  // an odd last bucket stays as it is
    const double* c = a + 2 * w;
    to[w] = c[w];  // the later bucket's last time
    for (std::size_t k = 1; k < w; ++k) {
      to[k] = lower(to[k], c[k]);
      to[w + k] = upper(to[w + k], c[w + k]);
    }
  }
  data_.resize(kept * 2 * w);
  stride_ *= 2;
}

int EnvelopeDecimator::rows() const {
  // At stride 1 a bucket's minima and maxima are the same row: it counts once.
  const auto per_bucket = static_cast<std::size_t>(stride_ == 1 ? 1 : 2);
  const std::size_t buckets = data_.size() / (2 * static_cast<std::size_t>(width_));
  return static_cast<int>(buckets * per_bucket + (in_bucket_ > 0 ? 2 : 0));
}

const double* EnvelopeDecimator::row(int i) const {
  const auto w = static_cast<std::size_t>(width_);
  const std::size_t closed = data_.size() / w;  // rows stored, minima and maxima
  const auto index = static_cast<std::size_t>(stride_ == 1 ? 2 * i : i);
  if (index < closed) return data_.data() + index * w;
  return open_.data() + (index - closed) * w;
}

void EnvelopeDecimator::write(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw Error(path.string() + ": cannot create the file");
  std::string line;
  for (int i = 0; i < rows(); ++i) write_row(out, line, row(i), width_);
  out.flush();
  if (!out) throw Error(path.string() + ": write failed (disk full?)");
}

std::string_view to_string(FigureFormat format) noexcept {
  switch (format) {
    case FigureFormat::kSvg:
      return "svg";
    case FigureFormat::kPdf:
      return "pdf";
    case FigureFormat::kPng:
      break;
  }
  return "png";
}

std::optional<FigureFormat> parse_figure_format(std::string_view text) noexcept {
  for (const FigureFormat f : {FigureFormat::kPng, FigureFormat::kSvg, FigureFormat::kPdf}) {
    if (text == to_string(f)) return f;
  }
  return std::nullopt;
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

void run_gnuplot(const std::filesystem::path& script) { run_gnuplot(script, {}); }

void run_gnuplot(const std::filesystem::path& script, const std::filesystem::path& output) {
  if (!gnuplot_available()) {
    throw Error(
        "gnuplot not found on the PATH: figures need it (Debian: sudo apt-get install "
        "gnuplot-nox); or pass --no-figures");
  }
  const std::filesystem::path dir = script.parent_path().empty() ? "." : script.parent_path();
  std::string command = "cd " + shell_quote(dir.string()) + " && gnuplot ";
  if (!output.empty()) {
    // -e's argument is shell-quoted; inside it, the gnuplot string is double-quoted.
    std::string value;
    for (const char c : output.filename().string()) {
      if (c == '"' || c == '\\') value += '\\';
      value += c;
    }
    command += "-e " + shell_quote("out = \"" + value + "\"") + " ";
  }
  command += shell_quote(script.filename().string()) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw Error("cannot run gnuplot for " + script.string());
  std::string messages;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) messages += buffer;
  const int status = pclose(pipe);
  if (status != 0 || messages.find("rror") != std::string::npos) {
    throw Error("gnuplot failed on " + script.string() + ":\n" + messages);
  }
}

std::string gnuplot_png_preamble(const std::filesystem::path& png, int width, int height) {
  std::ostringstream s;
  s << "set terminal pngcairo size " << width << "," << height
    << " enhanced font 'DejaVu Sans,11'\n"
    << "set output " << gnuplot_quote(png.filename().string()) << "\n"
    << "set grid\nset key outside right top\n";
  return s.str();
}

// NaN in the data is gnuplot's "invalid" value (no `set datafile missing 'NaN'`): a line stops
// at it, so a series is not drawn across spans without a value (no contact, a partial estimate).
std::string gnuplot_preamble(const std::filesystem::path& file, FigureFormat format, int width,
                             int height) {
  std::ostringstream s;
  switch (format) {
    case FigureFormat::kPng:
      s << "set terminal pngcairo size " << width << "," << height;
      break;
    case FigureFormat::kSvg:
      s << "set terminal svg size " << width << "," << height << " dynamic";
      break;
    case FigureFormat::kPdf:  // 100 pixels to the inch, as the PNG at its size
      s << "set terminal pdfcairo size " << width / 100.0 << "in," << height / 100.0 << "in";
      break;
  }
  s << " enhanced font 'DejaVu Sans,11'\n"
    << "if (!exists('out')) out = " << gnuplot_quote(file.filename().string()) << "\n"
    << "set output out\n"
    << "set grid\nset key outside right top\n";
  return s.str();
}

}  // namespace extwrench
