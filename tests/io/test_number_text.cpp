// The one strict-number rule (io/number_text.hpp) and what each format adds to it.
#include <gtest/gtest.h>

#include <limits>
#include <numbers>

#include "extwrench/io/number_text.hpp"

namespace extwrench {
namespace {

TEST(ParseNumber, AcceptsOnlyAWholeFiniteNumber) {
  EXPECT_EQ(parse_number("1.25"), 1.25);
  EXPECT_EQ(parse_number("+2e3"), 2000.0);
  EXPECT_EQ(parse_number("-.5"), -0.5);
  for (const char* bad : {"", " 1", "1 ", "abc", "1e", "nan", "inf", "0x1", "1,5", "+", "-", "+-1",
                          "++1", "1e999", "pi"}) {
    EXPECT_EQ(parse_number(bad), std::nullopt) << "'" << bad << "'";
  }
}

TEST(ParseNumber, TrimSpaceIgnoresOnlySurroundingWhiteSpace) {
  constexpr NumberRules kTrim{.trim_space = true};
  EXPECT_EQ(parse_number(" 1.5\t\n", kTrim), 1.5);
  EXPECT_EQ(parse_number(" +3 ", kTrim), 3.0);
  for (const char* bad : {"", "  ", "1 2", "1.0x", "nan", " inf "}) {
    EXPECT_EQ(parse_number(bad, kTrim), std::nullopt) << "'" << bad << "'";
  }
}

TEST(ParseNumber, InfinityOnlyWhenTheFormatAllowsIt) {
  constexpr NumberRules kInf{.infinity = true};
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(parse_number("inf", kInf), inf);
  EXPECT_EQ(parse_number(".inf", kInf), inf);
  EXPECT_EQ(parse_number("2", kInf), 2.0);
  for (const char* bad : {"-inf", "+inf", "infinity", "nan", ".nan"}) {
    EXPECT_EQ(parse_number(bad, kInf), std::nullopt) << "'" << bad << "'";
  }
}

TEST(ParseNumber, PiExpressionsOnlyWhenTheFormatAllowsIt) {
  constexpr NumberRules kAngle{.trim_space = true, .pi = true};
  constexpr double kPi = std::numbers::pi;
  EXPECT_EQ(parse_number("pi", kAngle), kPi);
  EXPECT_EQ(parse_number(" -pi/2 ", kAngle), -kPi / 2);
  EXPECT_EQ(parse_number("2*pi/3", kAngle), kPi * 2 / 3);
  EXPECT_EQ(parse_number("0.5*pi", kAngle), kPi * 0.5);
  EXPECT_EQ(parse_number("+pi", kAngle), kPi);
  EXPECT_EQ(parse_number("1.5", kAngle), 1.5);
  for (const char* bad : {"pi/0", "pi/", "*pi", "-2*pi/-3", "2 * pi", "pi pi", "2pi", "pix"}) {
    EXPECT_EQ(parse_number(bad, kAngle), std::nullopt) << "'" << bad << "'";
  }
}

TEST(ScanNumber, TellsOutOfRangeFromNotANumber) {
  double v = 0.0;
  EXPECT_EQ(scan_number("1e999", v), NumberScan::kOutOfRange);
  EXPECT_EQ(scan_number("1.2.3", v), NumberScan::kNotANumber);
  EXPECT_EQ(scan_number("nan", v), NumberScan::kOk);
  EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(scan_number("-inf", v), NumberScan::kOk);
  EXPECT_EQ(v, -std::numeric_limits<double>::infinity());
}

TEST(FormatNumber, WritesTheShortestTextThatReadsBack) {
  EXPECT_EQ(format_number(0.1), "0.1");
  EXPECT_EQ(format_number(-2.5e-7), "-2.5e-07");
  EXPECT_EQ(format_number(3.0), "3");
  EXPECT_EQ(format_number(std::numeric_limits<double>::infinity()), "inf");
  for (const double x : {0.1, 1.0 / 3.0, 6.02214076e23, -1e-300}) {
    EXPECT_EQ(parse_number(format_number(x)), x);
  }
}

}  // namespace
}  // namespace extwrench
