// The figures' decimation: the min/max envelope keeps every extreme of the stream (a
// one-sample singular peak survives any length), in bounded memory, in time order; checked
// against the stream itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "extwrench/app/gnuplot.hpp"

namespace extwrench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(EnvelopeDecimator, ASingleSamplePeakSurvivesAMillionRows) {
  constexpr long kRows = 1'000'000;
  constexpr long kPeakAt = 612'345;
  EnvelopeDecimator d(3, 500);
  double max_seen = -1.0, min_seen = 1e300;
  for (long i = 0; i < kRows; ++i) {
    const double t = 1e-3 * static_cast<double>(i);
    const double cond = i == kPeakAt ? 1.2e8 : 10.0 + std::sin(t);  // the singular instant
    const double flag = i % 1000 < 3 ? kNaN : 1.0;                  // gaps of "no estimate"
    const double row[3] = {t, cond, flag};
    max_seen = std::max(max_seen, cond);
    min_seen = std::min(min_seen, cond);
    d.push(row);
  }
  ASSERT_LE(d.rows(), 2 * 500 + 2);  // bounded, whatever the length
  double max_kept = -1.0, min_kept = 1e300, t_prev = -1.0, t_of_max = kNaN;
  for (int i = 0; i < d.rows(); ++i) {
    const double* r = d.row(i);
    EXPECT_GE(r[0], t_prev) << "rows stay in time order";
    t_prev = r[0];
    if (r[1] > max_kept) {
      max_kept = r[1];
      t_of_max = r[0];
    }
    min_kept = std::min(min_kept, r[1]);
    EXPECT_EQ(r[2], 1.0) << "NaN only where a whole bucket had no value";
  }
  EXPECT_EQ(max_kept, max_seen);
  EXPECT_EQ(min_kept, min_seen);
  // The peak is drawn within its bucket's span: rows / kept rows samples at most.
  EXPECT_NEAR(t_of_max, 1e-3 * kPeakAt, 1e-3 * (2.0 * kRows / d.rows()));
}

TEST(EnvelopeDecimator, AShortStreamIsKeptAsItIs) {
  EnvelopeDecimator d(2, 100);
  for (int i = 0; i < 50; ++i) {
    const double row[2] = {static_cast<double>(i), i % 7 == 0 ? kNaN : 2.0 * i};
    d.push(row);
  }
  ASSERT_EQ(d.rows(), 50);
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(d.row(i)[0], i);
    if (i % 7 == 0) {
      EXPECT_TRUE(std::isnan(d.row(i)[1]));
    } else {
      EXPECT_EQ(d.row(i)[1], 2.0 * i);
    }
  }
}

TEST(FigureFormat, NamesRoundTrip) {
  for (const FigureFormat f : {FigureFormat::kPng, FigureFormat::kSvg, FigureFormat::kPdf})
    EXPECT_EQ(parse_figure_format(to_string(f)), f);
  EXPECT_FALSE(parse_figure_format("jpg").has_value());
}

}  // namespace
}  // namespace extwrench
