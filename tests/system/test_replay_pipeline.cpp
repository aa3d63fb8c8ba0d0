// replay_log runs in three threads (reader, estimator, writer) handing batches of rows along, or
// on one (ReplayOptions::pipelined false, a replay given one core). Both checked against the
// plain loop, run here: the same bytes in estimates.csv, the same error text after the same
// rows, however the rows fall in batches.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "extwrench/app/replay.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/log.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "support/random.hpp"
#include "support/text_files.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;
using test::read_text;
using test::write_text;

const fs::path kPaperArm = fs::path(EXTWRENCH_SOURCE_DIR) / "models" / "paper_arm.urdf";
// Rows per hand-off between the threads (kBatchRows in replay.cpp); the tests put rows and
// errors on both sides of batch boundaries and past a full turn of the ring (4 batches).
constexpr long kBatch = 1024;

class ReplayPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    robot_ = std::make_unique<RobotDescription>(load_robot(kPaperArm));
    dir_ = fs::temp_directory_path() /
           ("extwrench_test_replay_pipeline_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
    robot_.reset();
  }
  static std::unique_ptr<RobotDescription> robot_;
  static fs::path dir_;
};
std::unique_ptr<RobotDescription> ReplayPipeline::robot_;
fs::path ReplayPipeline::dir_;

/// A log of `rows` rows at 1 kHz: smooth joint motion, a noisy F/T reading, a push on link 6
/// from row 300 (so the estimates go through free, pending and contact).
void write_log(const fs::path& path, long rows, bool velocity) {
  LogLayout layout{.n = 7,
                   .velocity = velocity,
                   .force = true,
                   .moment = true,
                   .truth = true,
                   .true_tau_ext = false};
  LogWriter w(path, layout);
  test::SeededRng rng(11);
  Sample s;
  s.q.resize(7);
  s.dq.resize(7);
  s.tau.resize(7);
  for (long k = 0; k < rows; ++k) {
    const double t = 0.001 * static_cast<double>(k);
    for (int i = 0; i < 7; ++i) {
      s.q[i] = 0.4 * std::sin(0.7 * t + i);
      s.dq[i] = 0.28 * std::cos(0.7 * t + i);
      s.tau[i] = 8.0 * std::sin(0.5 * t + i) + rng.uniform(-0.5, 0.5);
    }
    s.t = t;
    const bool push = k >= 300;
    s.reading_S << rng.uniform(-1, 1) + (push ? 15.0 : 0.0), rng.uniform(-1, 1),
        -170 + rng.uniform(-1, 1), rng.uniform(-0.1, 0.1),
        rng.uniform(-0.1, 0.1) + (push ? 6.0 : 0.0), rng.uniform(-0.1, 0.1);
    s.truth.link = push ? "link6" : "";
    s.truth.body = push ? 6 : -1;
    s.truth.force_W << (push ? 15.0 : 0.0), 0, 0;
    s.truth.point_W << 0.1, 0.0, 0.6;
    w.write(s);
  }
  w.close();
}

/// The log with data row `row` (0-based) replaced by `text` (a malformed row).
void corrupt_row(const fs::path& from, const fs::path& to, long row, const std::string& text) {
  std::istringstream in(read_text(from));
  std::string out, line;
  for (long k = -1; std::getline(in, line); ++k) out += (k == row ? text : line) + "\n";
  write_text(to, out);
}

/// The same data row with cell `cell` (0-based) replaced.
std::string row_with_cell(const fs::path& log, long row, int cell, const std::string& value) {
  std::istringstream in(read_text(log));
  std::string line;
  for (long k = -1; std::getline(in, line) && k < row; ++k) {
  }
  std::vector<std::string> cells;
  std::stringstream s(line);
  for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  cells.at(static_cast<std::size_t>(cell)) = value;
  std::string joined;
  for (std::size_t i = 0; i < cells.size(); ++i) joined += (i ? "," : "") + cells[i];
  return joined;
}

struct Outcome {
  std::string error;      // empty when it succeeded
  std::string estimates;  // the bytes of estimates.csv
};

/// The loop replay_log ran before it was split into threads: one row read, estimated and
/// written after the other, on the calling thread.
Outcome plain_loop(const RobotDescription& robot, const EstimatorOptions& options,
                   const fs::path& log, const fs::path& out_dir) {
  fs::create_directories(out_dir);
  Outcome o;
  try {
    LogReader reader(log, robot.model);
    ContactEstimator estimator(robot.model, robot.geometry, options);
    const int n = robot.model.nq();
    EstimatesWriter writer(out_dir / "estimates.csv", robot.model);
    Sample s;
    bool started = false;
    while (reader.next(s)) {
      if (!started) {
        ContactEstimate first;
        first.t = s.t;
        first.residual = VectorX::Zero(n);
        first.status = estimator.reset(s.t, s.q, s.dq, s.tau);
        started = first.status.ok();
        writer.write(first);
      } else {
        (void)(options.sensor.type == SensorType::kNone
                   ? estimator.update(s.t, s.q, s.dq, s.tau)
                   : estimator.update(s.t, s.q, s.dq, s.tau, s.reading_S));
        writer.write(estimator.result());
      }
    }
    writer.close();
  } catch (const Error& e) {
    o.error = e.what();
  }
  o.estimates = read_text(out_dir / "estimates.csv");
  return o;
}

Outcome replayed(const RobotDescription& robot, const EstimatorOptions& options,
                 const fs::path& log, const fs::path& out_dir, bool pipelined) {
  ReplayOptions ro;
  ro.log = log;
  ro.out_dir = out_dir;
  ro.figures = false;
  ro.pipelined = pipelined;
  Outcome o;
  try {
    const ReplayResult r = replay_log(robot.model, robot.geometry, options, ro);
    EXPECT_GT(r.rows, 0);
  } catch (const Error& e) {
    o.error = e.what();
  }
  o.estimates = read_text(out_dir / "estimates.csv");
  return o;
}

long lines_of(const std::string& text) {
  return static_cast<long>(std::count(text.begin(), text.end(), '\n'));
}

EstimatorOptions ft_options() {
  EstimatorOptions options;
  options.sensor.type = SensorType::kForceTorque;
  return options;
}

TEST_F(ReplayPipeline, WritesTheSameBytesAsThePlainLoopWhateverTheNumberOfBatches) {
  // Fewer rows than a batch; more than a turn of the ring, ending in a partial batch.
  for (const long rows : {long{700}, 4 * kBatch + 3}) {
    const fs::path log = dir_ / ("log_" + std::to_string(rows) + ".csv");
    write_log(log, rows, true);
    const fs::path out = dir_ / ("same_" + std::to_string(rows));
    const Outcome expected = plain_loop(*robot_, ft_options(), log, out / "plain");
    ASSERT_EQ(expected.error, "") << rows;
    for (const bool pipelined : {true, false}) {
      const Outcome got = replayed(*robot_, ft_options(), log,
                                   out / (pipelined ? "pipelined" : "one_thread"), pipelined);
      EXPECT_EQ(got.error, "") << rows;
      EXPECT_EQ(lines_of(got.estimates), rows + 1);
      EXPECT_TRUE(got.estimates == expected.estimates)
          << rows << " rows, pipelined " << pipelined << ": estimates differ";
      // Several status texts went through the writer's cache.
      EXPECT_NE(got.estimates.find(",free,"), std::string::npos);
      EXPECT_NE(got.estimates.find("contact|"), std::string::npos);
    }
  }
}

TEST_F(ReplayPipeline, LogWithoutVelocitiesIsDifferentiatedAcrossBatchesAsInThePlainLoop) {
  const fs::path log = dir_ / "no_dq.csv";
  write_log(log, 2 * kBatch + 17, false);
  EstimatorOptions options;  // no sensor: the other update()
  const Outcome expected = plain_loop(*robot_, options, log, dir_ / "no_dq" / "plain");
  ASSERT_EQ(expected.error, "");
  for (const bool pipelined : {true, false}) {
    const Outcome got =
        replayed(*robot_, options, log, dir_ / "no_dq" / std::to_string(pipelined), pipelined);
    EXPECT_EQ(got.error, "");
    EXPECT_TRUE(got.estimates == expected.estimates) << "pipelined " << pipelined;
  }
}

TEST_F(ReplayPipeline, MalformedRowFailsWithTheSameTextAfterTheSameRowsAsThePlainLoop) {
  const long rows = 4 * kBatch + 2;
  const fs::path good = dir_ / "good.csv";
  write_log(good, rows, true);
  struct Case {
    long row;  // 0-based data row that is malformed
    int cell;  // 0-based cell replaced
    std::string value;
    std::string expected;  // part of the message
  };
  const std::vector<Case> cases = {
      {0, 2, "abc", ":2: column 3 'q2': expected a number, got 'abc'"},
      {kBatch - 1, 2, "abc", ":1025: column 3 'q2': expected a number, got 'abc'"},
      {kBatch, 20, "", ":1026: column 21 'tau6': empty cell, expected a number"},
      {2 * kBatch + 5, 0, "0.001", ":2055: column 1 't': time must increase (0.001 after 2.05"},
      {rows - 1, 28, "link9",
       ":4099: column 29 'true_link': 'link9' is not a link of robot 'paper_arm'"},
  };
  for (const Case& c : cases) {
    const std::string name = "bad_" + std::to_string(c.row);
    const fs::path log = dir_ / (name + ".csv");
    corrupt_row(good, log, c.row, row_with_cell(good, c.row, c.cell, c.value));
    const Outcome expected = plain_loop(*robot_, ft_options(), log, dir_ / name / "plain");
    EXPECT_NE(expected.error.find(c.expected), std::string::npos) << expected.error;
    for (const bool pipelined : {true, false}) {
      const fs::path out = dir_ / name / std::to_string(pipelined);
      const Outcome got = replayed(*robot_, ft_options(), log, out, pipelined);
      EXPECT_EQ(got.error, expected.error);
      // A failed replay leaves no output, not even the rows before the bad one (docs/cli.md).
      EXPECT_FALSE(fs::exists(out)) << c.row << ", pipelined " << pipelined;
    }
  }
}

TEST_F(ReplayPipeline, MalformedSecondRowOfALogWithoutVelocitiesFailsBeforeAnyRowIsWritten) {
  // The first row's q̇ is a forward difference: the second row is read before the first is
  // returned, so its error comes first.
  const fs::path good = dir_ / "no_dq_good.csv";
  write_log(good, 50, false);
  const fs::path log = dir_ / "no_dq_bad.csv";
  corrupt_row(good, log, 1, row_with_cell(good, 1, 3, "x"));
  const Outcome expected =
      plain_loop(*robot_, EstimatorOptions{}, log, dir_ / "no_dq_bad" / "plain");
  for (const bool pipelined : {true, false}) {
    const fs::path out = dir_ / "no_dq_bad" / std::to_string(pipelined);
    const Outcome got = replayed(*robot_, EstimatorOptions{}, log, out, pipelined);
    EXPECT_NE(got.error.find(":3: column 4 'q3': expected a number, got 'x'"), std::string::npos)
        << got.error;
    EXPECT_EQ(got.error, expected.error);
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST_F(ReplayPipeline, AFailedWriteStopsTheReplayWithTheWritersError) {
  // estimates.csv on a full disk: the writer fails at its first flush, while the reader still
  // has rows; the error must come out, not a hang.
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path log = dir_ / "for_full_disk.csv";
  write_log(log, 4 * kBatch, true);  // ~1.5 MB of estimates: the first 1 MiB flush fails mid-log
  for (const bool pipelined : {true, false}) {
    const fs::path out = dir_ / "full_disk" / std::to_string(pipelined);
    fs::create_directories(out);
    // The replay writes estimates.csv.partial, renamed when complete.
    fs::create_symlink("/dev/full", out / "estimates.csv.partial");
    ReplayOptions ro;
    ro.log = log;
    ro.out_dir = out;
    ro.figures = false;
    ro.pipelined = pipelined;
    std::string error;
    try {
      (void)replay_log(robot_->model, robot_->geometry, ft_options(), ro);
    } catch (const Error& e) {
      error = e.what();
    }
    EXPECT_NE(error.find("estimates.csv.partial: write failed"), std::string::npos) << error;
    // Nothing of the failed replay remains.
    EXPECT_FALSE(fs::exists(out / "estimates.csv"));
    EXPECT_FALSE(fs::is_symlink(out / "estimates.csv.partial"));
  }
}

}  // namespace
}  // namespace extwrench
