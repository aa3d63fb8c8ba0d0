// Streaming CSV: a reader that holds one row at a time (logs of millions of rows replay in
// constant memory) and a writer whose doubles read back bit for bit.
//
// Dialect and policies (docs/cli.md restates them for users):
//  - The first non-empty line is the header; columns are looked up by name. Names must be
//    unique and non-empty.
//  - Separator ','; lines end in LF or CRLF; empty (or blank) lines are skipped anywhere; a
//    UTF-8 byte-order mark before the header is ignored.
//  - Cells may be quoted ("a,b", "say ""hi"""); a quoted cell cannot span lines. Spaces and
//    tabs around a cell are trimmed.
//  - Every row has exactly as many cells as the header.
//  - Numbers are parsed strictly (io/number_text.hpp: std::from_chars, '.' decimal point, optional
//  exponent, an
//    optional leading '+'); anything left over ("1.5x", "1,5", "0x10") is an error.
//    number() also rejects empty cells, nan and inf; number_or_nan() reads an empty cell or
//    "nan" as NaN and accepts inf / -inf.
//  - The writer writes doubles in the shortest form that reads back to the same double
//    (std::to_chars), NaN as an empty cell, infinities as inf / -inf.
// Errors throw extwrench::Error naming file, line and column, e.g.
//   "states.csv:12: column 3 'q2': expected a number, got '1.2.3'".
#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace extwrench {

/// Limits of the reader (docs/cli.md "Limits"): a longer line or a row (or header) with more
/// cells is an error naming file and line, so memory stays bounded by them whatever the input.
inline constexpr std::size_t kCsvMaxLineBytes = std::size_t{16} << 20;  // 16 MiB
inline constexpr std::size_t kCsvMaxColumns = 100'000;

class CsvReader {
 public:
  /// Opens `path` and reads its header. Throws extwrench::Error if the file cannot be opened,
  /// has no header, or the header is malformed (empty or duplicate names).
  explicit CsvReader(const std::filesystem::path& path);
  /// Reads from a stream the caller keeps alive; `name` stands for the file in messages.
  CsvReader(std::istream& in, std::string name);
  ~CsvReader();
  CsvReader(const CsvReader&) = delete;
  CsvReader& operator=(const CsvReader&) = delete;
  CsvReader(CsvReader&&) noexcept;
  CsvReader& operator=(CsvReader&&) noexcept;

  /// File name used in error messages.
  [[nodiscard]] const std::string& name() const { return name_; }
  /// Column names, in file order.
  [[nodiscard]] const std::vector<std::string>& header() const { return header_; }
  [[nodiscard]] int num_columns() const { return static_cast<int>(header_.size()); }
  /// Index of the column of that name, if any.
  [[nodiscard]] std::optional<int> find_column(std::string_view column_name) const;
  /// Index of the column of that name; throws "<file>:<line>: missing column '<name>'".
  [[nodiscard]] int column(std::string_view column_name) const;
  /// For a missing-column message: when the header is a single column holding ';' or a tab
  /// (a spreadsheet's export in a locale whose separator is not ','), a sentence saying so;
  /// else empty.
  [[nodiscard]] std::string separator_hint() const;

  /// Advances to the next non-empty row. Returns false at the end of the file. Throws if the
  /// row has the wrong number of cells or an unterminated quote.
  bool next_row();
  /// 1-based line number of the current row (of the header before the first next_row()).
  [[nodiscard]] std::size_t line() const { return row_line_; }
  /// Number of data rows read so far.
  [[nodiscard]] std::size_t rows_read() const { return rows_read_; }

  /// Text of a cell of the current row, trimmed and unquoted; valid until next_row().
  [[nodiscard]] std::string_view cell(int column) const;
  [[nodiscard]] bool is_empty(int column) const { return cell(column).empty(); }
  /// The cell as a finite number; throws naming file, line and column otherwise.
  [[nodiscard]] double number(int column) const;
  /// The cell as a number, NaN if it is empty or "nan"; infinities accepted.
  [[nodiscard]] double number_or_nan(int column) const;

  /// "<file>:<line>: column <k> '<name>': " (k 1-based), to start an error message about a cell.
  [[nodiscard]] std::string where(int column) const;
  /// "<file>:<line>: ", to start an error message about the current row.
  [[nodiscard]] std::string where() const;

 private:
  void read_header();
  bool read_line();
  void refill();
  void split_line();
  void split_quoted_line();
  [[noreturn]] void too_many_columns() const;
  [[noreturn]] void fail_number(int column, std::string_view reason) const;
  double parse(int column, bool allow_missing) const;

  std::unique_ptr<std::ifstream> owned_stream_;
  std::istream* in_ = nullptr;
  std::string name_;
  std::vector<std::string> header_;
  std::unordered_map<std::string, int> column_index_;

  // Read buffer: lines are found with memchr and parsed where they lie (no copy); a line cut by
  // the end of the buffer is moved to its front before the next read.
  std::vector<char> buffer_;
  std::size_t buffer_pos_ = 0;
  std::size_t buffer_end_ = 0;
  bool eof_ = false;

  std::string_view line_;  // the current line in buffer_ (CR stripped)
  std::string unquoted_;   // storage for quoted cells with "" escapes
  std::vector<std::string_view> cells_;
  std::size_t next_line_ = 1;  // number of the next line to be read
  std::size_t row_line_ = 0;
  std::size_t rows_read_ = 0;
};

class CsvWriter {
 public:
  /// Creates (truncates) `path` and writes the header. Throws extwrench::Error if the file
  /// cannot be created.
  CsvWriter(const std::filesystem::path& path, std::vector<std::string> header);
  /// Writes to a stream the caller keeps alive; `name` stands for the file in messages.
  CsvWriter(std::ostream& out, std::vector<std::string> header, std::string name = "<stream>");
  /// Flushes; errors at that point are lost, call close() to see them.
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  [[nodiscard]] const std::vector<std::string>& header() const { return header_; }

  /// Appends a cell to the current row: shortest round-trip form, NaN as an empty cell.
  CsvWriter& add(double value);
  CsvWriter& add(int value);
  CsvWriter& add(long long value);
  CsvWriter& add(std::size_t value);
  /// Text, quoted when it contains a separator, a quote, a line break or outer spaces.
  CsvWriter& add(std::string_view text);
  CsvWriter& add(const char* text) { return add(std::string_view(text)); }
  CsvWriter& add_empty();
  /// Ends the row; throws extwrench::Error if it does not have as many cells as the header.
  void end_row();
  /// Writes buffered rows out; throws extwrench::Error on a write failure (disk full, ...).
  void flush();
  /// flush(), then closes an owned file.
  void close();

  /// Shortest decimal text that reads back to the same double ("0.1", "1e-300", "inf"); NaN
  /// gives "nan". The formatting used by add(double): format_number (io/number_text.hpp).
  static std::string format(double value);
  /// Appends format(value) to `out` without a temporary string.
  static void append(std::string& out, double value);

 private:
  char* room(std::size_t bytes);  // the end of the buffer, with `bytes` free after it
  void grow(std::size_t needed);
  char* separator(std::size_t bytes);  // room() for the ',' (if any) and `bytes` after it

  std::unique_ptr<std::ofstream> owned_stream_;
  std::ostream* out_ = nullptr;
  std::string name_;
  std::vector<std::string> header_;
  // Cells are formatted straight into this buffer (std::to_chars, no temporaries); it goes out
  // in one write() per ~1 MiB of whole rows.
  std::unique_ptr<char[]> buffer_;
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
  std::size_t row_start_ = 0;  // where the current row begins in buffer_
  std::size_t cells_in_row_ = 0;
};

}  // namespace extwrench
