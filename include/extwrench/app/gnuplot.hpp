// Figures with gnuplot (run as a subprocess on a script and whitespace-separated data files),
// and a streaming decimator so that figures of hour-long logs cost constant memory.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
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
    return data_.data() + static_cast<std::size_t>(i) * static_cast<std::size_t>(width_);
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

/// Keeps the envelope of a stream of equally long rows (column 0 is time) in about
/// 2·max_points rows: the rows are cut into buckets of `stride` consecutive rows (1, then 2, 4,
/// ... as the stream grows: adjacent buckets merge when the buffer fills), and each bucket
/// becomes two rows, the per-column minima at the bucket's first time and the maxima at its
/// last time (NaN only when the column is NaN throughout the bucket). A line through them covers
/// every value of the stream, so a one-sample peak survives any decimation. Memory is
/// independent of the stream's length.
class EnvelopeDecimator {
 public:
  EnvelopeDecimator(int width, int max_points);
  void push(const double* values);
  [[nodiscard]] int width() const { return width_; }
  /// Rows of the envelope, the open bucket's included.
  [[nodiscard]] int rows() const;
  [[nodiscard]] const double* row(int i) const;
  /// Writes the rows as whitespace-separated text (NaN as "NaN", which gnuplot skips).
  void write(const std::filesystem::path& path) const;

 private:
  void close_bucket();
  void merge_pairs();

  int width_;
  int max_points_;
  long long stride_ = 1;
  long long in_bucket_ = 0;   // rows in the open bucket
  std::vector<double> open_;  // its minima row then its maxima row
  std::vector<double> data_;  // closed buckets: minima row, maxima row, ...
};

/// Output format of the figures (`--figure-format`).
enum class FigureFormat { kPng, kSvg, kPdf };

/// "png", "svg", "pdf".
[[nodiscard]] std::string_view to_string(FigureFormat format) noexcept;
/// The format named by "png", "svg" or "pdf"; nullopt otherwise.
[[nodiscard]] std::optional<FigureFormat> parse_figure_format(std::string_view text) noexcept;

/// True when a `gnuplot` executable is on the PATH.
[[nodiscard]] bool gnuplot_available();

/// Runs `gnuplot script` in the script's directory. Throws extwrench::Error with gnuplot's
/// messages when it fails, or a clear message when gnuplot is missing
/// ("gnuplot not found ... apt-get install gnuplot-nox ... or --no-figures").
void run_gnuplot(const std::filesystem::path& script);

/// The same, with the gnuplot variable `out` set to `output` (the scripts of
/// gnuplot_preamble() write to `out` when it is set: a temporary name, renamed on success).
void run_gnuplot(const std::filesystem::path& script, const std::filesystem::path& output);

/// A gnuplot string literal (single quotes doubled).
[[nodiscard]] std::string gnuplot_quote(const std::string& text);

/// The common preamble of our PNG figures: pngcairo, size, font, grid, key placement.
[[nodiscard]] std::string gnuplot_png_preamble(const std::filesystem::path& png, int width = 1000,
                                               int height = 700);

/// The preamble for any format (pngcairo, svg, pdfcairo; size in PNG pixels, scaled for PDF):
/// the output is the variable `out` when set on gnuplot's command line, else `file`'s name, so
/// that a script run by hand writes the figure under its own name.
[[nodiscard]] std::string gnuplot_preamble(const std::filesystem::path& file, FigureFormat format,
                                           int width = 1000, int height = 700);

}  // namespace extwrench
