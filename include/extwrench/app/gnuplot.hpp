// Figures with gnuplot (run as a subprocess on a script and whitespace-separated data files),
// and a streaming decimator so that figures of hour-long logs cost constant memory.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace extwrench {

/// Keeps at most about 2·max_points rows of a stream of equally long rows: every row while
/// they fit, then every 2nd, 4th, ... (the stride doubles and the kept rows are thinned each
/// time the buffer fills). Memory is independent of the stream's length; rows stay in order
/// and evenly spaced in index.
class Decimator {
 public:
  Decimator(int width, int max_points);
  /// Whether the next row would be kept (call before computing expensive columns).
  [[nodiscard]] bool wants_next() const { return index_ % stride_ == 0; }
  /// Offers the next row (width values); keeps it if it falls on the stride.
  void push(const double* values);
  /// Skips the next row without offering it (when wants_next() was false).
  void skip() { ++index_; }
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int rows() const {
    return static_cast<int>(data_.size() / static_cast<std::size_t>(width_));
  }
  [[nodiscard]] const double* row(int i) const {
    return data_.data() + static_cast<std::size_t>(i) * width_;
  }
  /// Writes the rows as whitespace-separated text (NaN as "NaN", which gnuplot skips).
  void write(const std::filesystem::path& path) const;

 private:
  int width_;
  int max_points_;
  long long index_ = 0;
  long long stride_ = 1;
  std::vector<double> data_;
};

/// True when a `gnuplot` executable is on the PATH.
[[nodiscard]] bool gnuplot_available();

/// Runs `gnuplot script` in the script's directory. Throws extwrench::Error with gnuplot's
/// messages when it fails, or a clear message when gnuplot is missing
/// ("gnuplot not found ... apt-get install gnuplot-nox ... or --no-figures").
void run_gnuplot(const std::filesystem::path& script);

/// A gnuplot string literal (single quotes doubled).
[[nodiscard]] std::string gnuplot_quote(const std::string& text);

/// The common preamble of our PNG figures: pngcairo, size, font, grid, key placement.
[[nodiscard]] std::string gnuplot_png_preamble(const std::filesystem::path& png, int width = 1000,
                                               int height = 700);

}  // namespace extwrench
