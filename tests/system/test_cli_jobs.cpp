// `--jobs N` of `extwrench estimate` over several logs and of `simulate` over seeds and schemes
// (issue 15): the same bytes as one-log runs and as the serial run, the console in input order,
// a bad log named while the good ones keep their outputs, and N < 1 a usage error.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "extwrench/io/log.hpp"
#include "support/scratch_dir.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

const fs::path kPaperArm = fs::path(EXTWRENCH_SOURCE_DIR) / "models" / "paper_arm.urdf";

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Every occurrence of `from` in `text` replaced by `to` (output paths differ between runs).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

struct CliRun {
  int code = -1;
  std::string out, err;
};

// A log of the paper arm's format whose signals depend on `phase`: every log differs, so a
// mix-up between logs shows in the bytes. A push on link 6 for t in [1, 2) s (truth columns).
void write_log(const fs::path& path, double phase, long rows) {
  constexpr int n = 7;
  LogWriter w(path, LogLayout{.n = n,
                              .velocity = true,
                              .force = true,
                              .moment = true,
                              .truth = true,
                              .true_tau_ext = true});
  Sample s;
  s.q.resize(n);
  s.dq.resize(n);
  s.tau.resize(n);
  s.truth.tau_ext = VectorX::Zero(n);
  for (long k = 0; k < rows; ++k) {
    s.t = 0.001 * static_cast<double>(k);
    for (int i = 0; i < n; ++i) {
      s.q[i] = 0.4 * std::sin(0.7 * s.t + i + phase);
      s.dq[i] = 0.28 * std::cos(0.7 * s.t + i + phase);
      s.tau[i] = 8.0 * std::sin(0.5 * s.t + i + phase);
    }
    const bool contact = s.t >= 1.0 && s.t < 2.0;
    s.reading_S << 1 + phase, 2, -170, 0.1, 0.2, 0.3;
    s.truth.link = contact ? "link6" : "";
    s.truth.body = contact ? 6 : -1;
    s.truth.contacts = contact ? 1 : 0;
    s.truth.force_W << (contact ? 20.0 : 0.0), 0, 0;
    s.truth.point_W << 0.1, 0.2, 0.8;
    w.write(s);
  }
  w.close();
}

class Jobs : public test::ScratchDirTest {
 protected:
  Jobs() : ScratchDirTest("extwrench_jobs") {}

  CliRun run(const std::string& args) const {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command = std::string("'") + EXTWRENCH_CLI + "' " + args + " >'" +
                                out.string() + "' 2>'" + err.string() + "' </dev/null";
    const int status = std::system(command.c_str());
    CliRun r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_text(out);
    r.err = read_text(err);
    return r;
  }
  fs::path path(const std::string& name) const { return dir_ / name; }
  static std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

  // Three different logs in dir_/logs and an F/T configuration.
  void write_inputs() {
    fs::create_directories(path("logs"));
    for (int i = 0; i < 3; ++i) write_log(path("logs") / logs_[i], 0.3 * i, 2500);
    write_text(path("config.yaml"), "robot: " + kPaperArm.string() + "\nsensor: {type: ft}\n");
  }
  std::string estimate(const std::string& logs, const fs::path& out, int jobs) const {
    return "estimate --no-figures --config " + q(path("config.yaml")) + " --log " + logs +
           " --out " + q(out) + " --jobs " + std::to_string(jobs);
  }
  // The log files, and what each one alone writes (the reference, today's one-log layout).
  const std::vector<std::string> logs_{"a.csv", "b.csv", "c.csv"};
  void expect_as_alone(const fs::path& several, const std::string& log) {
    const fs::path alone = path("alone") / fs::path(log).stem();
    if (!fs::exists(alone / "estimates.csv")) {
      const CliRun r = run(estimate(q(path("logs") / log), alone, 1));
      ASSERT_EQ(r.code, 0) << r.err;
    }
    const fs::path mine = several / fs::path(log).stem();
    for (const char* file : {"estimates.csv", "metrics.json"}) {
      ASSERT_TRUE(fs::exists(mine / file)) << mine / file;
      EXPECT_EQ(read_text(mine / file), read_text(alone / file)) << mine / file;
    }
  }
};

TEST_F(Jobs, SeveralLogsGiveTheBytesOfOneLogRunsWithOneOrThreeJobs) {
  write_inputs();
  const fs::path logs = path("logs");
  const CliRun one = run(estimate(
      q(logs / "a.csv") + " " + q(logs / "b.csv") + " --log " + q(logs / "c.csv"), path("j1"), 1));
  ASSERT_EQ(one.code, 0) << one.err;
  const CliRun three = run(estimate(q(logs / "*.csv"), path("j3"), 3));  // expanded by extwrench
  ASSERT_EQ(three.code, 0) << three.err;
  for (const std::string& log : logs_) {
    expect_as_alone(path("j1"), log);
    expect_as_alone(path("j3"), log);
  }
  // The console in input order, whatever the scheduling.
  EXPECT_EQ(replaced(three.out, path("j3").string(), "DIR"),
            replaced(one.out, path("j1").string(), "DIR"));
  const auto a = three.out.find("j3/a/estimates.csv"), c = three.out.find("j3/c/estimates.csv");
  EXPECT_TRUE(a != std::string::npos && c != std::string::npos && a < c) << three.out;
}

TEST_F(Jobs, ABadLogAmongGoodOnesIsNamedAndTheGoodOnesKeepTheirOutputs) {
  write_inputs();
  fs::copy_file(path("logs") / "b.csv", path("logs") / "bad.csv");
  std::ofstream(path("logs") / "bad.csv", std::ios::app) << "oops\n";
  const fs::path logs = path("logs");
  const CliRun r = run(estimate(
      q(logs / "a.csv") + " " + q(logs / "bad.csv") + " " + q(logs / "c.csv"), path("out"), 2));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("1 of 3 logs failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find((logs / "bad.csv").string() + ":2502:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("out") / "bad")) << "the failed log left files";
  expect_as_alone(path("out"), "a.csv");
  expect_as_alone(path("out"), "c.csv");
}

TEST_F(Jobs, ZeroOrNegativeJobsAndClashingLogNamesAreUsageErrors) {
  write_inputs();
  const std::string log = q(path("logs") / "a.csv");
  for (const char* jobs : {"0", "-1", "-3"}) {
    const CliRun e = run("estimate --no-figures --config " + q(path("config.yaml")) + " --log " +
                         log + " --out " + q(path("e")) + " --jobs " + jobs);
    EXPECT_EQ(e.code, 2) << jobs << ": " << e.err;
    EXPECT_NE(e.err.find("--jobs"), std::string::npos) << e.err;
    const CliRun s = run("simulate --no-figures " + q(path("none.yaml")) + " --out " +
                         q(path("s")) + " --jobs " + jobs);
    EXPECT_EQ(s.code, 2) << jobs << ": " << s.err;
  }
  fs::create_directories(path("other"));
  fs::copy_file(path("logs") / "a.csv", path("other") / "a.csv");
  const CliRun clash = run(estimate(log + " " + q(path("other") / "a.csv"), path("c"), 2));
  EXPECT_EQ(clash.code, 2) << clash.err;
  EXPECT_NE(clash.err.find("would both write"), std::string::npos) << clash.err;
  const CliRun nothing = run(estimate(q(path("logs") / "*.tsv"), path("n"), 2));
  EXPECT_EQ(nothing.code, 1) << nothing.err;
  EXPECT_NE(nothing.err.find("no file matches"), std::string::npos) << nothing.err;
  for (const char* d : {"e", "s", "c", "n"}) EXPECT_FALSE(fs::exists(path(d))) << d;
}

// Every file under `dir` with its bytes, the run's directory name replaced.
std::vector<std::pair<std::string, std::string>> tree(const fs::path& dir) {
  std::vector<std::pair<std::string, std::string>> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    files.emplace_back(fs::relative(e.path(), dir).string(),
                       replaced(read_text(e.path()), dir.string(), "DIR"));
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST_F(Jobs, SimulateWithTwoJobsWritesTheBytesOfTheSerialRun) {
  write_text(path("s.yaml"), "robot: " + kPaperArm.string() +
                                 "\nseeds: [4, 7, 9]\nduration: 1.5\ntrajectory: {offset: 0.3, "
                                 "amplitude: 0.2, frequency: 0.5, phase: 0}\nforces:\n  - {frame: "
                                 "link6, axes: frame, force: [20, 0, 0], point: [0, 0, 0.1], "
                                 "start: 0.5}\nschemes:\n  ft: {sensor: {type: ft}}\n  "
                                 "no_sensor: {sensor: {type: none}}\n");
  const CliRun one =
      run("simulate --no-figures " + q(path("s.yaml")) + " --out " + q(path("one")) + " --jobs 1");
  ASSERT_EQ(one.code, 0) << one.err;
  const CliRun two =
      run("simulate --no-figures " + q(path("s.yaml")) + " --out " + q(path("two")) + " --jobs 2");
  ASSERT_EQ(two.code, 0) << two.err;
  const auto serial = tree(path("one")), parallel = tree(path("two"));
  // 3 seeds × (log, model, 2 × (config, estimates, metrics)).
  EXPECT_EQ(serial.size(), 3u * 8u);
  ASSERT_EQ(parallel.size(), serial.size());
  for (std::size_t i = 0; i < serial.size(); ++i) {
    EXPECT_EQ(parallel[i].first, serial[i].first);
    EXPECT_TRUE(parallel[i].second == serial[i].second) << parallel[i].first << " differs";
  }
  EXPECT_EQ(replaced(two.out, path("two").string(), "DIR"),
            replaced(one.out, path("one").string(), "DIR"));
}

}  // namespace
}  // namespace extwrench
