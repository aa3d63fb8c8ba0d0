#include "extwrench/io/csv.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <istream>
#include <limits>
#include <ostream>
#include <system_error>
#include <unordered_map>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/output_files.hpp"

namespace extwrench {
namespace {

constexpr std::size_t kReadChunk = std::size_t{1} << 18;   // 256 KiB per read()
constexpr std::size_t kWriteChunk = std::size_t{1} << 20;  // flush the writer every 1 MiB
constexpr std::size_t kMaxNumberChars = 32;  // the shortest form of a double: at most 24 chars
constexpr std::size_t kShownCellChars = 40;  // longer cells are cut in messages

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

std::string shown(std::string_view cell) {
  if (cell.size() <= kShownCellChars) return std::string(cell);
  return std::string(cell.substr(0, kShownCellChars)) + "...";
}

}  // namespace

// ------------------------------------------------------------------------------------------
// CsvReader

CsvReader::CsvReader(const std::filesystem::path& path) : name_(path.string()) {
  // A FIFO or a device would be read without end (or block): regular files only; a stream is
  // read through the other constructor, when a command says so ('-').
  if (std::error_code ec; std::filesystem::exists(path, ec)) check_input_file(path, "CSV");
  owned_stream_ = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*owned_stream_) throw Error(name_ + ": cannot open the file for reading");
  in_ = owned_stream_.get();
  read_header();
}

CsvReader::CsvReader(std::istream& in, std::string name) : in_(&in), name_(std::move(name)) {
  read_header();
}

CsvReader::~CsvReader() = default;
CsvReader::CsvReader(CsvReader&&) noexcept = default;
CsvReader& CsvReader::operator=(CsvReader&&) noexcept = default;

bool CsvReader::read_line() {
  for (;;) {
    const char* begin = buffer_.data() + buffer_pos_;
    const std::size_t available = buffer_end_ - buffer_pos_;
    const void* newline = available > 0 ? std::memchr(begin, '\n', available) : nullptr;
    if (newline != nullptr) {
      const auto length = static_cast<std::size_t>(static_cast<const char*>(newline) - begin);
      line_ = std::string_view(begin, length);
      buffer_pos_ += length + 1;
      break;
    }
    if (eof_) {
      if (available == 0) return false;
      line_ = std::string_view(begin, available);  // the last line has no line break
      buffer_pos_ = buffer_end_;
      break;
    }
    refill();
  }
  if (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);  // CRLF
  row_line_ = next_line_++;
  return true;
}

void CsvReader::refill() {
  // Keep the unfinished line, at the front; a line as long as the buffer doubles it.
  const std::size_t kept = buffer_end_ - buffer_pos_;
  if (kept > 0 && buffer_pos_ > 0) std::memmove(buffer_.data(), buffer_.data() + buffer_pos_, kept);
  buffer_pos_ = 0;
  buffer_end_ = kept;
  if (buffer_.size() < kReadChunk) {
    buffer_.resize(kReadChunk);
  } else if (kept == buffer_.size()) {
    // The cap keeps memory independent of the input: a line without end is an error, not a
    // buffer as large as the file.
    if (kept >= kCsvMaxLineBytes) {
      throw Error(name_ + ":" + std::to_string(next_line_) + ": line longer than " +
                  std::to_string(kCsvMaxLineBytes) + " bytes (the limit, docs/cli.md)");
    }
    buffer_.resize(std::min(2 * buffer_.size(), kCsvMaxLineBytes));
  }
  const std::size_t wanted = buffer_.size() - kept;
  in_->read(buffer_.data() + kept, static_cast<std::streamsize>(wanted));
  const auto got = static_cast<std::size_t>(in_->gcount());
  buffer_end_ += got;
  if (got < wanted) {
    if (in_->bad()) throw Error(name_ + ":" + std::to_string(next_line_) + ": read error");
    eof_ = true;
  }
}

void CsvReader::split_line() {
  cells_.clear();
  // Fast path, no quotes: one pass over the line for ',' (and '"', which sends the line to the
  // slow path), 16 bytes at a time.
  const char* const begin = line_.data();
  const std::size_t size = line_.size();
  std::size_t start = 0;  // of the current cell
  std::size_t i = 0;
  auto cut = [&](std::size_t comma) {
    if (cells_.size() + 1 >= kCsvMaxColumns) too_many_columns();
    cells_.push_back(trim(std::string_view(begin + start, comma - start)));
    start = comma + 1;
  };
#if defined(__SSE2__)
  const __m128i comma = _mm_set1_epi8(',');
  const __m128i quote = _mm_set1_epi8('"');
  for (; i + 16 <= size; i += 16) {
    const __m128i chunk = _mm_loadu_si128(reinterpret_cast<const __m128i*>(begin + i));
    if (_mm_movemask_epi8(_mm_cmpeq_epi8(chunk, quote)) != 0) return split_quoted_line();
    auto commas = static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(chunk, comma)));
    while (commas != 0) {
      cut(i + static_cast<std::size_t>(std::countr_zero(commas)));
      commas &= commas - 1;
    }
  }
#endif
  for (; i < size; ++i) {
    if (begin[i] == ',') {
      cut(i);
    } else if (begin[i] == '"') {
      return split_quoted_line();
    }
  }
  cells_.push_back(trim(std::string_view(begin + start, size - start)));
}

void CsvReader::too_many_columns() const {
  throw Error(where() + "more than " + std::to_string(kCsvMaxColumns) +
              " columns (the limit, docs/cli.md)");
}

void CsvReader::split_quoted_line() {
  cells_.clear();
  const std::string_view line = line_;
  // Quoted cells: unescaped text goes to unquoted_, reserved so the views stay valid.
  unquoted_.clear();
  unquoted_.reserve(line.size());
  std::size_t i = 0;
  for (;;) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i < line.size() && line[i] == '"') {
      const std::size_t first_column = cells_.size() + 1;
      const std::size_t start = unquoted_.size();
      ++i;
      bool closed = false;
      while (i < line.size()) {
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            unquoted_.push_back('"');
            i += 2;
            continue;
          }
          closed = true;
          ++i;
          break;
        }
        unquoted_.push_back(line[i++]);
      }
      if (!closed) {
        throw Error(where() + "column " + std::to_string(first_column) +
                    ": unterminated quoted cell (a quoted cell cannot span lines)");
      }
      if (cells_.size() + 1 >= kCsvMaxColumns) too_many_columns();
      cells_.emplace_back(unquoted_.data() + start, unquoted_.size() - start);
      while (i < line.size() && is_blank(line[i])) ++i;
      if (i < line.size() && line[i] != ',') {
        throw Error(where() + "column " + std::to_string(first_column) +
                    ": unexpected text after a closing quote");
      }
    } else {
      const std::size_t comma = std::min(line.find(',', i), line.size());
      const std::string_view cell = trim(line.substr(i, comma - i));
      if (cell.find('"') != std::string_view::npos) {
        throw Error(
            where() + "column " + std::to_string(cells_.size() + 1) +
            ": a quote inside an unquoted cell (quote the whole cell and double the quote)");
      }
      if (cells_.size() + 1 >= kCsvMaxColumns) too_many_columns();
      cells_.push_back(cell);
      i = comma;
    }
    if (i >= line.size()) break;
    ++i;  // the comma
  }
}

void CsvReader::read_header() {
  for (;;) {
    if (!read_line()) throw Error(name_ + ": empty file: expected a header row of column names");
    if (row_line_ == 1 && line_.starts_with("\xEF\xBB\xBF")) line_.remove_prefix(3);  // UTF-8 BOM
    if (!trim(line_).empty()) break;
  }
  // A robot file given where a CSV belongs (`--log arm.urdf`): say so, not "a quote inside an
  // unquoted cell" of its XML declaration. No header of column names begins with '<'.
  if (trim(line_).starts_with('<')) {
    throw Error(where() + xml_given_instead("a CSV file begins with a header row of column names"));
  }
  split_line();
  header_.assign(cells_.begin(), cells_.end());
  column_index_.clear();  // a hash map: wide logs have many columns
  column_index_.reserve(header_.size());
  for (std::size_t k = 0; k < header_.size(); ++k) {
    if (header_[k].empty()) {
      throw Error(where() + "column " + std::to_string(k + 1) + " of the header has an empty name");
    }
    const auto [it, inserted] = column_index_.emplace(header_[k], static_cast<int>(k));
    if (!inserted) {
      throw Error(where() + "column " + std::to_string(k + 1) + " '" + header_[k] +
                  "' appears twice in the header (also column " + std::to_string(it->second + 1) +
                  ")");
    }
  }
  cells_.clear();
}

std::optional<int> CsvReader::find_column(std::string_view column_name) const {
  const auto it = column_index_.find(std::string(column_name));
  if (it == column_index_.end()) return std::nullopt;
  return it->second;
}

int CsvReader::column(std::string_view column_name) const {
  if (const auto c = find_column(column_name)) return *c;
  throw Error(name_ + ":1: missing column '" + std::string(column_name) + "'" + separator_hint());
}

std::string CsvReader::separator_hint() const {
  if (header_.size() != 1) return {};
  const std::string& only = header_.front();
  const char* separator = only.find(';') != std::string::npos    ? "';'"
                          : only.find('\t') != std::string::npos ? "a tab"
                                                                 : nullptr;
  if (separator == nullptr) return {};
  return std::string("; the header is a single column whose name holds ") + separator +
         ": the separator must be ',' (docs/cli.md#csv-files-all-commands)";
}

bool CsvReader::next_row() {
  for (;;) {
    if (!read_line()) {
      cells_.clear();
      return false;
    }
    if (!trim(line_).empty()) break;  // blank lines are skipped
  }
  split_line();
  if (cells_.size() != header_.size()) {
    throw Error(where() + "expected " + std::to_string(header_.size()) +
                " cells as in the header, got " + std::to_string(cells_.size()));
  }
  ++rows_read_;
  return true;
}

std::string_view CsvReader::cell(int column) const {
  if (column < 0 || static_cast<std::size_t>(column) >= cells_.size()) {
    throw Error(where() + "no cell " + std::to_string(column + 1) + " in this row");
  }
  return cells_[static_cast<std::size_t>(column)];
}

std::string CsvReader::where() const { return name_ + ":" + std::to_string(row_line_) + ": "; }

std::string CsvReader::where(int column) const {
  std::string s = where() + "column " + std::to_string(column + 1);
  if (column >= 0 && static_cast<std::size_t>(column) < header_.size()) {
    s += " '" + header_[static_cast<std::size_t>(column)] + "'";
  }
  return s + ": ";
}

void CsvReader::fail_number(int column, std::string_view reason) const {
  throw Error(where(column) + std::string(reason));
}

double CsvReader::parse(int column, bool allow_missing) const {
  const std::string_view s = cell(column);
  if (s.empty()) {
    if (allow_missing) return std::numeric_limits<double>::quiet_NaN();
    fail_number(column, "empty cell, expected a number");
  }
  double value = 0.0;
  const NumberScan result = scan_number(s, value);
  if (result == NumberScan::kOutOfRange) {
    fail_number(column, "number out of the range of a double: '" + shown(s) + "'");
  }
  if (result != NumberScan::kOk) fail_number(column, "expected a number, got '" + shown(s) + "'");
  if (std::isnan(value)) {
    if (allow_missing) return std::numeric_limits<double>::quiet_NaN();
    fail_number(column, "expected a finite number, got '" + shown(s) + "'");
  }
  if (std::isinf(value) && !allow_missing) {
    fail_number(column, "expected a finite number, got '" + shown(s) + "'");
  }
  return value;
}

double CsvReader::number(int column) const {
  double value = 0.0;
  if (static_cast<std::size_t>(column) < cells_.size() &&
      parse_plain_number(cells_[static_cast<std::size_t>(column)], value)) {
    return value;
  }
  return parse(column, false);  // the rest, with messages that name what is wrong
}

double CsvReader::number_or_nan(int column) const {
  double value = 0.0;
  if (static_cast<std::size_t>(column) < cells_.size() &&
      parse_plain_number(cells_[static_cast<std::size_t>(column)], value)) {
    return value;
  }
  return parse(column, true);
}

// ------------------------------------------------------------------------------------------
// CsvWriter

namespace {
std::unique_ptr<std::ofstream> open_truncated(const std::filesystem::path& path) {
  errno = 0;  // so that a failure's errno is open(2)'s
  auto out = std::make_unique<std::ofstream>(path, std::ios::binary | std::ios::trunc);
  if (!*out) throw Error(OutputFiles::cannot_create(path, errno));
  return out;
}
}  // namespace

CsvWriter::CsvWriter(const std::filesystem::path& path, std::vector<std::string> header)
    : owned_stream_(open_truncated(path)), name_(path.string()), header_(std::move(header)) {
  out_ = owned_stream_.get();
  if (header_.empty()) throw Error(name_ + ": a CSV file needs at least one column");
  for (const auto& h : header_) add(std::string_view(h));
  end_row();
}

CsvWriter::CsvWriter(std::ostream& out, std::vector<std::string> header, std::string name)
    : out_(&out), name_(std::move(name)), header_(std::move(header)) {
  if (header_.empty()) throw Error(name_ + ": a CSV file needs at least one column");
  for (const auto& h : header_) add(std::string_view(h));
  end_row();
}

CsvWriter::~CsvWriter() {
  try {
    flush();
  } catch (...) {  // NOLINT(bugprone-empty-catch): a destructor must not throw; close() reports
  }
}

void CsvWriter::append(std::string& out, double value) { append_number(out, value); }

std::string CsvWriter::format(double value) { return format_number(value); }

char* CsvWriter::room(std::size_t bytes) {
  if (size_ + bytes > capacity_) grow(size_ + bytes);
  return buffer_.get() + size_;
}

void CsvWriter::grow(std::size_t needed) {
  // Whole rows are flushed, so a row longer than the chunk grows the buffer instead.
  const std::size_t capacity = std::max({needed, 2 * capacity_, kWriteChunk + 4096});
  auto bigger = std::make_unique_for_overwrite<char[]>(capacity);
  if (size_ > 0) std::memcpy(bigger.get(), buffer_.get(), size_);
  buffer_ = std::move(bigger);
  capacity_ = capacity;
}

char* CsvWriter::separator(std::size_t bytes) {
  char* p = room(bytes + 1);
  if (cells_in_row_++ > 0) {
    *p++ = ',';
    ++size_;
  }
  return p;
}

CsvWriter& CsvWriter::add(double value) {
  char* p = separator(kMaxNumberChars);
  if (!std::isnan(value)) {
    const auto [end, ec] = std::to_chars(p, p + kMaxNumberChars, value);
    (void)ec;  // cannot fail with 32 characters
    size_ += static_cast<std::size_t>(end - p);
  }
  return *this;
}

CsvWriter& CsvWriter::add(long long value) {
  char* p = separator(kMaxNumberChars);
  const auto [end, ec] = std::to_chars(p, p + kMaxNumberChars, value);
  (void)ec;
  size_ += static_cast<std::size_t>(end - p);
  return *this;
}

CsvWriter& CsvWriter::add(int value) { return add(static_cast<long long>(value)); }
CsvWriter& CsvWriter::add(std::size_t value) { return add(static_cast<long long>(value)); }

CsvWriter& CsvWriter::add(std::string_view text) {
  bool needs_quotes = !text.empty() && (is_blank(text.front()) || is_blank(text.back()));
  for (std::size_t i = 0; i < text.size() && !needs_quotes; ++i) {
    const char c = text[i];
    needs_quotes = c == ',' || c == '"' || c == '\r' || c == '\n';
  }
  if (!needs_quotes) {
    char* p = separator(text.size());
    if (!text.empty()) std::memcpy(p, text.data(), text.size());
    size_ += text.size();
    return *this;
  }
  char* p = separator(2 * text.size() + 2);  // every character a quote, doubled
  const char* const begin = p;
  *p++ = '"';
  for (const char c : text) {
    if (c == '"') *p++ = '"';
    *p++ = c;
  }
  *p++ = '"';
  size_ += static_cast<std::size_t>(p - begin);
  return *this;
}

CsvWriter& CsvWriter::add_empty() {
  (void)separator(0);
  return *this;
}

void CsvWriter::end_row() {
  if (cells_in_row_ != header_.size()) {
    const std::size_t got = cells_in_row_;
    size_ = row_start_;  // drop the incomplete row
    cells_in_row_ = 0;
    throw Error(name_ + ": internal error: a row of " + std::to_string(got) + " cells for " +
                std::to_string(header_.size()) + " columns");
  }
  *room(1) = '\n';
  ++size_;
  cells_in_row_ = 0;
  if (size_ >= kWriteChunk) flush();
  row_start_ = size_;
}

void CsvWriter::flush() {
  if (out_ == nullptr) return;
  if (size_ > 0) {
    out_->write(buffer_.get(), static_cast<std::streamsize>(size_));
    size_ = 0;
    row_start_ = 0;
  }
  out_->flush();
  if (!*out_) throw Error(name_ + ": write failed (disk full or file removed?)");
}

void CsvWriter::close() {
  flush();
  if (owned_stream_) {
    owned_stream_->close();
    if (!*owned_stream_) throw Error(name_ + ": closing the file failed");
  }
  out_ = nullptr;
}

}  // namespace extwrench
