// Hostile CSV input (issue 14): a line without end or a row of commas is refused at the
// documented caps (kCsvMaxLineBytes, kCsvMaxColumns) with file:line, and the reader's memory
// stays bounded by the caps, not by the input. The input is generated on the fly (1 GiB, never
// stored); peak memory is measured in a forked child with getrusage.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <istream>
#include <streambuf>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/io/csv.hpp"
#include "support/build_info.hpp"

namespace extwrench {
namespace {

constexpr std::size_t kGiB = std::size_t{1} << 30;

// `head`, then `count` copies of `fill`, produced 64 KiB at a time.
class GeneratedInput : public std::streambuf {
 public:
  GeneratedInput(std::string head, char fill, std::size_t count)
      : head_(std::move(head)), fill_(fill), left_(count), chunk_(std::size_t{1} << 16, fill) {
    setg(head_.data(), head_.data(), head_.data() + head_.size());
  }

 protected:
  int_type underflow() override {
    if (left_ == 0) return traits_type::eof();
    const std::size_t n = std::min(left_, chunk_.size());
    left_ -= n;
    setg(chunk_.data(), chunk_.data(), chunk_.data() + n);
    return traits_type::to_int_type(fill_);
  }

 private:
  std::string head_;
  char fill_;
  std::size_t left_;
  std::string chunk_;
};

long max_rss_kb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

struct Outcome {
  std::string message;
  long rss_growth_kb = -1;
};

// Reads the whole generated input in a child process; returns the error and the growth of the
// child's peak resident set.
Outcome read_in_child(const std::string& head, char fill, std::size_t count) {
  int fd[2];
  if (pipe(fd) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    const long before = max_rss_kb();
    std::string msg = "accepted";
    try {
      GeneratedInput buf(head, fill, count);
      std::istream in(&buf);
      CsvReader reader(in, "gen.csv");
      while (reader.next_row()) {
      }
    } catch (const Error& e) {
      msg = e.what();
    }
    const std::string out = std::to_string(max_rss_kb() - before) + " " + msg;
    (void)!write(fd[1], out.data(), out.size());
    _exit(0);
  }
  close(fd[1]);
  std::string text;
  char chunk[4096];
  for (ssize_t n; (n = read(fd[0], chunk, sizeof chunk)) > 0;)
    text.append(chunk, static_cast<std::size_t>(n));
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  Outcome o;
  const auto space = text.find(' ');
  if (space == std::string::npos) return o;
  o.rss_growth_kb = std::stol(text.substr(0, space));
  o.message = text.substr(space + 1);
  return o;
}

// 1 GiB would cost 3-4 GB before the caps; allow the 16 MiB line buffer and some slack.
constexpr long kMaxGrowthKb = 64 * 1024;

TEST(CsvLimits, AGibibyteLineIsRefusedInBoundedMemory) {
  const Outcome o = read_in_child("t,q1\n", 'x', kGiB);
  std::printf("1 GiB line: peak RSS growth %ld KiB: %s\n", o.rss_growth_kb, o.message.c_str());
  EXPECT_EQ(o.message.rfind("gen.csv:2: line longer than 16777216 bytes", 0), 0u) << o.message;
  EXPECT_GE(o.rss_growth_kb, 0);
  if (!test::kSanitizerBuild) {
    EXPECT_LT(o.rss_growth_kb, kMaxGrowthKb);
  }
}

TEST(CsvLimits, AGibibyteOfCommasIsRefusedInBoundedMemory) {
  const Outcome o = read_in_child("t,q1\n", ',', kGiB);
  std::printf("1 GiB of commas: peak RSS growth %ld KiB: %s\n", o.rss_growth_kb, o.message.c_str());
  EXPECT_EQ(o.message.rfind("gen.csv:2: line longer than", 0), 0u) << o.message;
  EXPECT_GE(o.rss_growth_kb, 0);
  if (!test::kSanitizerBuild) {
    EXPECT_LT(o.rss_growth_kb, kMaxGrowthKb);
  }
}

TEST(CsvLimits, TooManyColumnsAreRefusedNamingTheLine) {
  // 1 MiB of commas: within the line cap, 10 times the column cap.
  const Outcome o = read_in_child("t,q1\n1,2\n", ',', std::size_t{1} << 20);
  EXPECT_EQ(o.message, "gen.csv:3: more than 100000 columns (the limit, docs/cli.md)");
  if (!test::kSanitizerBuild) {
    EXPECT_LT(o.rss_growth_kb, kMaxGrowthKb);
  }
  const Outcome header = read_in_child("", ',', std::size_t{1} << 20);
  EXPECT_EQ(header.message, "gen.csv:1: more than 100000 columns (the limit, docs/cli.md)");
}

}  // namespace
}  // namespace extwrench
