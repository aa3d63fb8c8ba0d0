// The streaming CSV reader and writer (io/csv.hpp): dialect, strict numbers, error messages
// naming file, line and column, bit-exact round trip of doubles, streaming across buffer
// boundaries.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/io/csv.hpp"
#include "support/error_of.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::error_of;

/// Passes when `needle` occurs in `text`; prints both otherwise.
::testing::AssertionResult contains(const std::string& text, const std::string& needle) {
  if (text.find(needle) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << needle << "'";
}

/// Reads every row of `text`, converting every cell with number(): the error it throws.
std::string error_reading_numbers(const std::string& text, const std::string& name = "data.csv") {
  return error_of([&] {
    std::istringstream in(text);
    CsvReader reader(in, name);
    while (reader.next_row()) {
      for (int c = 0; c < reader.num_columns(); ++c) (void)reader.number(c);
    }
  });
}

TEST(CsvReader, FindsColumnsByNameAndReadsRowsInOrder) {
  std::istringstream in("t,q1,q2\n0,1.5,-2\n0.001,3e-3,+4\n");
  CsvReader reader(in, "states.csv");
  EXPECT_EQ(reader.header(), (std::vector<std::string>{"t", "q1", "q2"}));
  EXPECT_EQ(reader.column("q2"), 2);
  EXPECT_EQ(reader.find_column("q3"), std::nullopt);
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.line(), 2u);
  EXPECT_EQ(reader.number(reader.column("q1")), 1.5);
  EXPECT_EQ(reader.number(reader.column("q2")), -2.0);
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.number(0), 0.001);
  EXPECT_EQ(reader.number(1), 3e-3);
  EXPECT_EQ(reader.number(2), 4.0);
  EXPECT_FALSE(reader.next_row());
  EXPECT_EQ(reader.rows_read(), 2u);
}

TEST(CsvReader, NamesTheFileInTheMissingColumnError) {
  std::istringstream in("t,q1\n");
  CsvReader reader(in, "log.csv");
  EXPECT_EQ(error_of([&] { (void)reader.column("dq1"); }), "log.csv:1: missing column 'dq1'");
}

// A spreadsheet saved in a locale whose list separator is ';' (or as tab-separated text) gives a
// header of one column: the error says why every column seems missing.
TEST(CsvReader, AHeaderOfOneColumnHoldingSemicolonsOrTabsNamesTheSeparator) {
  for (const auto& [text, separator] :
       {std::pair{"t;q1;q2\n0;1;2\n", "';'"}, std::pair{"t\tq1\tq2\n0\t1\t2\n", "a tab"}}) {
    std::istringstream in(text);
    CsvReader reader(in, "log.csv");
    EXPECT_EQ(error_of([&] { (void)reader.column("q1"); }),
              std::string("log.csv:1: missing column 'q1'; the header is a single column whose "
                          "name holds ") +
                  separator + ": the separator must be ',' (docs/cli.md#csv-files-all-commands)");
  }
  std::istringstream plain("t\n0\n");  // one column, nothing odd in it: no hint
  EXPECT_EQ(error_of([&] { (void)CsvReader(plain, "log.csv").column("q1"); }),
            "log.csv:1: missing column 'q1'");
}

TEST(CsvReader, AcceptsCrlfBlankLinesByteOrderMarkAndNoFinalNewline) {
  std::istringstream in("\xEF\xBB\xBFt , x\r\n\r\n1, 2\r\n   \n\t\n3,4");
  CsvReader reader(in, "crlf.csv");
  EXPECT_EQ(reader.header(), (std::vector<std::string>{"t", "x"}));
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.line(), 3u);  // physical lines, blank ones counted
  EXPECT_EQ(reader.number(1), 2.0);
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.line(), 6u);
  EXPECT_EQ(reader.number(0), 3.0);
  EXPECT_EQ(reader.number(1), 4.0);
  EXPECT_FALSE(reader.next_row());
}

TEST(CsvReader, SkipsBlankLinesBeforeTheHeader) {
  std::istringstream in("\n\n a,b \n1,2\n");
  CsvReader reader(in, "x.csv");
  EXPECT_EQ(reader.header(), (std::vector<std::string>{"a", "b"}));
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.line(), 4u);
}

TEST(CsvReader, UnquotesQuotedCellsWithSeparatorsQuotesAndSpaces) {
  std::istringstream in(
      "name,comment,v\n\"link,6\", \"say \"\"hi\"\"\" ,\"  7 \"\n\"\",x,\"\"\"\"\n");
  CsvReader reader(in, "q.csv");
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.cell(0), "link,6");
  EXPECT_EQ(reader.cell(1), "say \"hi\"");
  EXPECT_EQ(reader.cell(2), "  7 ");  // spaces inside quotes are kept
  ASSERT_TRUE(reader.next_row());
  EXPECT_TRUE(reader.is_empty(0));
  EXPECT_EQ(reader.cell(1), "x");
  EXPECT_EQ(reader.cell(2), "\"");
}

TEST(CsvReader, NumberRejectsEmptyNanAndInfinityButNumberOrNanAcceptsThem) {
  std::istringstream in("a,b,c,d\n,nan,inf,-inf\n");
  CsvReader reader(in, "n.csv");
  ASSERT_TRUE(reader.next_row());
  EXPECT_TRUE(std::isnan(reader.number_or_nan(0)));
  EXPECT_TRUE(std::isnan(reader.number_or_nan(1)));
  EXPECT_EQ(reader.number_or_nan(2), std::numeric_limits<double>::infinity());
  EXPECT_EQ(reader.number_or_nan(3), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(error_of([&] { (void)reader.number(0); }),
            "n.csv:2: column 1 'a': empty cell, expected a number");
  EXPECT_EQ(error_of([&] { (void)reader.number(1); }),
            "n.csv:2: column 2 'b': expected a finite number, got 'nan'");
  EXPECT_EQ(error_of([&] { (void)reader.number(2); }),
            "n.csv:2: column 3 'c': expected a finite number, got 'inf'");
  // Text is still an error for number_or_nan: only empty and nan mean "missing".
  std::istringstream in2("a\nabc\n");
  CsvReader reader2(in2, "n2.csv");
  ASSERT_TRUE(reader2.next_row());
  EXPECT_EQ(error_of([&] { (void)reader2.number_or_nan(0); }),
            "n2.csv:2: column 1 'a': expected a number, got 'abc'");
}

// Each malformed input with the exact file:line and column text its message must contain.
struct MalformedCase {
  const char* what;
  const char* text;
  const char* expected;
};

TEST(CsvReader, MalformedInputsAreReportedWithFileLineAndColumn) {
  const std::vector<MalformedCase> cases = {
      {"letters", "t,q1\n0,1\n0.1,abc\n", "bad.csv:3: column 2 'q1': expected a number, got 'abc'"},
      {"two decimal points", "t,q1\n0,1.2.3\n",
       "bad.csv:2: column 2 'q1': expected a number, got '1.2.3'"},
      {"trailing garbage", "t,q1\n0.5x,1\n",
       "bad.csv:2: column 1 't': expected a number, got '0.5x'"},
      {"decimal comma in quotes", "t,q1\n0,\"1,5\"\n",
       "bad.csv:2: column 2 'q1': expected a number, got '1,5'"},
      {"hexadecimal", "t,q1\n0,0x10\n", "bad.csv:2: column 2 'q1': expected a number, got '0x10'"},
      {"double sign", "t,q1\n0,+-1\n", "bad.csv:2: column 2 'q1': expected a number, got '+-1'"},
      {"double minus", "t,q1\n0,--1\n", "bad.csv:2: column 2 'q1': expected a number, got '--1'"},
      {"inner space", "t,q1\n0,1 2\n", "bad.csv:2: column 2 'q1': expected a number, got '1 2'"},
      {"empty cell", "t,q1\n0,1\n1,\n", "bad.csv:3: column 2 'q1': empty cell, expected a number"},
      {"not finite", "t,q1\n0,NaN\n",
       "bad.csv:2: column 2 'q1': expected a finite number, got 'NaN'"},
      {"overflow", "t,q1\n0,1e999\n",
       "bad.csv:2: column 2 'q1': number out of the range of a double: '1e999'"},
      {"too few cells", "t,q1,q2\n0,1,2\n0,1\n",
       "bad.csv:3: expected 3 cells as in the header, got 2"},
      {"too many cells (trailing comma)", "t,q1\n0,1,\n",
       "bad.csv:2: expected 2 cells as in the header, got 3"},
      {"unterminated quote", "t,q1\n0,\"1\n", "bad.csv:2: column 2: unterminated quoted cell"},
      {"text after a quote", "t,q1\n0,\"1\"2\n",
       "bad.csv:2: column 2: unexpected text after a closing quote"},
      {"stray quote", "t,q1\n0,1\"\n", "bad.csv:2: column 2: a quote inside an unquoted cell"},
      {"line counted across CRLF and blank lines", "t,q1\r\n0,1\r\n\r\n\r\n2,x\r\n",
       "bad.csv:5: column 2 'q1': expected a number, got 'x'"},
      {"duplicate column", "t,q1,q1\n",
       "bad.csv:1: column 3 'q1' appears twice in the header (also column 2)"},
      {"empty column name", "t,,q1\n", "bad.csv:1: column 2 of the header has an empty name"},
      {"a robot file (XML) given for a CSV",
       "\xEF\xBB\xBF\n  <?xml version=\"1.0\"?>\n<robot name=\"a\">\n",
       "bad.csv:2: this is XML (a URDF or MJCF robot file?), but a CSV file begins with a header "
       "row of column names"},
      {"empty file", "", "bad.csv: empty file: expected a header row"},
      {"blank file", "\n \r\n", "bad.csv: empty file: expected a header row"},
  };
  for (const MalformedCase& c : cases) {
    SCOPED_TRACE(c.what);
    EXPECT_TRUE(contains(error_reading_numbers(c.text, "bad.csv"), c.expected));
  }
  EXPECT_GE(cases.size(), 8u);
}

TEST(CsvReader, CutsVeryLongCellsInMessages) {
  const std::string message = error_reading_numbers("a\nz" + std::string(1000, '7') + "\n");
  EXPECT_TRUE(contains(message, "got 'z777"));
  EXPECT_LT(message.size(), 200u);
}

TEST(CsvReader, ReportsAFileThatCannotBeOpened) {
  const std::string message =
      error_of([] { CsvReader reader(std::filesystem::path("/nonexistent/dir/x.csv")); });
  EXPECT_EQ(message, "/nonexistent/dir/x.csv: cannot open the file for reading");
}

/// An input stream that generates `rows` rows of varying length on the fly, so that a long
/// input never exists in memory and lines straddle the reader's chunks at every offset.
class GeneratedRows : public std::streambuf {
 public:
  explicit GeneratedRows(std::size_t rows) : rows_(rows) { refill("i,x,pad\n"); }

  static double value(std::size_t i) { return static_cast<double>(i) * 0.001 - 1.0 / 3.0; }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    if (next_ >= rows_) return traits_type::eof();
    std::string text;
    for (int k = 0; k < 64 && next_ < rows_; ++k, ++next_) {
      text += std::to_string(next_) + "," + CsvWriter::format(value(next_)) + "," +
              std::string(next_ % 37, 'p') + (next_ % 5 == 0 ? "\r\n" : "\n");
    }
    refill(text);
    return traits_type::to_int_type(*gptr());
  }

 private:
  void refill(const std::string& text) {
    chunk_ = text;
    setg(chunk_.data(), chunk_.data(), chunk_.data() + chunk_.size());
  }
  std::size_t rows_;
  std::size_t next_ = 0;
  std::string chunk_;
};

TEST(CsvReader, StreamsManyRowsWhoseLinesStraddleReadChunks) {
  constexpr std::size_t kRows = 200000;  // ~6 MB of text, > 20 read chunks
  GeneratedRows source(kRows);
  std::istream in(&source);
  CsvReader reader(in, "generated.csv");
  const int ci = reader.column("i");
  const int cx = reader.column("x");
  std::size_t expected = 0;
  while (reader.next_row()) {
    ASSERT_EQ(reader.number(ci), static_cast<double>(expected));
    ASSERT_EQ(reader.number(cx), GeneratedRows::value(expected));
    ASSERT_EQ(reader.cell(2).size(), expected % 37);
    ++expected;
  }
  EXPECT_EQ(expected, kRows);
  EXPECT_EQ(reader.line(), kRows + 1);
}

TEST(CsvReader, ReadsALineLongerThanTheReadChunk) {
  constexpr int kColumns = 40000;  // ~0.5 MB header and row
  std::string header;
  std::string row;
  for (int c = 0; c < kColumns; ++c) {
    header += (c ? ",c" : "c") + std::to_string(c);
    row += (c ? "," : "") + std::to_string(c);
  }
  std::istringstream in(header + "\n" + row + "\n");
  CsvReader reader(in, "wide.csv");
  ASSERT_EQ(reader.num_columns(), kColumns);
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.number(reader.column("c39999")), 39999.0);
  EXPECT_EQ(reader.number(reader.column("c12345")), 12345.0);
}

TEST(CsvWriter, DoublesReadBackBitForBit) {
  test::SeededRng rng(2026);
  std::vector<double> values = {0.1,
                                1.0 / 3.0,
                                -0.0,
                                0.0,
                                1e-300,
                                std::numeric_limits<double>::denorm_min(),
                                std::numeric_limits<double>::min(),
                                std::numeric_limits<double>::max(),
                                -std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::epsilon(),
                                9007199254740993.0,
                                123456789.123456789};
  // Random bit patterns cover every exponent; non-finite ones are handled separately.
  while (values.size() < 5000) {
    const double v = std::bit_cast<double>(rng.bits());
    if (std::isfinite(v)) values.push_back(v);
  }
  std::stringstream io;
  {
    CsvWriter writer(io, {"v"}, "round_trip.csv");
    for (const double v : values) writer.add(v).end_row();
    writer.flush();
  }
  CsvReader reader(io, "round_trip.csv");
  for (const double v : values) {
    ASSERT_TRUE(reader.next_row());
    const double back = reader.number(0);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(back), std::bit_cast<std::uint64_t>(v))
        << reader.cell(0);
  }
  EXPECT_FALSE(reader.next_row());
}

TEST(CsvWriter, UsesTheShortestTextThatReadsBack) {
  EXPECT_EQ(CsvWriter::format(0.1), "0.1");
  EXPECT_EQ(CsvWriter::format(2.0), "2");
  EXPECT_EQ(CsvWriter::format(-1.5e-7), "-1.5e-07");
  EXPECT_EQ(CsvWriter::format(std::numeric_limits<double>::infinity()), "inf");
}

TEST(CsvWriter, WritesNanAsAnEmptyCellAndQuotesTextThatNeedsIt) {
  std::stringstream io;
  CsvWriter writer(io, {"t", "link", "fx", "note"});
  writer.add(0.5)
      .add("link6")
      .add(std::numeric_limits<double>::quiet_NaN())
      .add("a, \"b\"")
      .end_row();
  writer.add(1.0).add("").add(-std::numeric_limits<double>::infinity()).add(" padded ").end_row();
  writer.flush();
  EXPECT_EQ(io.str(), "t,link,fx,note\n0.5,link6,,\"a, \"\"b\"\"\"\n1,,-inf,\" padded \"\n");
  CsvReader reader(io, "w.csv");
  ASSERT_TRUE(reader.next_row());
  EXPECT_TRUE(std::isnan(reader.number_or_nan(2)));
  EXPECT_EQ(reader.cell(3), "a, \"b\"");
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.number_or_nan(2), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(reader.cell(3), " padded ");
}

TEST(CsvWriter, WritesIntegersExactly) {
  std::stringstream io;
  CsvWriter writer(io, {"a", "b", "c"});
  writer.add(-7).add(std::size_t{18446744073709}).add(1234567890123LL).end_row();
  writer.flush();
  EXPECT_EQ(io.str(), "a,b,c\n-7,18446744073709,1234567890123\n");
}

TEST(CsvWriter, RejectsARowWithTheWrongNumberOfCellsAndDropsIt) {
  std::stringstream io;
  CsvWriter writer(io, {"a", "b"}, "out.csv");
  writer.add(1.0);
  EXPECT_TRUE(contains(error_of([&] { writer.end_row(); }),
                       "out.csv: internal error: a row of 1 cells for 2 columns"));
  writer.add(1.0).add(2.0).end_row();
  writer.flush();
  EXPECT_EQ(io.str(), "a,b\n1,2\n");
}

TEST(CsvWriter, ReportsAFailedWrite) {
  std::ofstream closed;  // never opened: every write fails
  CsvWriter writer(closed, {"a"}, "closed.csv");
  writer.add(1.0).end_row();
  EXPECT_TRUE(contains(error_of([&] { writer.flush(); }), "closed.csv: write failed"));
}

TEST(CsvWriter, WritesAFileTheReaderReadsBack) {
  const auto path = std::filesystem::temp_directory_path() / "extwrench_test_csv_file.csv";
  {
    CsvWriter writer(path, {"t", "x"});
    writer.add(0.25).add(-3.0).end_row();
    writer.close();
  }
  CsvReader reader(path);
  EXPECT_EQ(reader.name(), path.string());
  ASSERT_TRUE(reader.next_row());
  EXPECT_EQ(reader.number(1), -3.0);
  EXPECT_FALSE(reader.next_row());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace extwrench
