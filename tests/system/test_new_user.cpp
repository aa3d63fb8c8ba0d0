// Issue 11, acceptance 1, as a new user on day one: the shared Panda URDF (a tree: its fingers
// locked, its meshes found with --package-path), the shared UR5 and the project's paper arm each
// go through `info`, `dynamics`, `simulate` (3 seeds, model_error 0.01, a push on a middle link:
// tests/data/new_user/*.yaml) and `estimate` on a copy of the simulated log with every truth
// column removed, for the sensor types ft, force and none. Every command exits 0, every figure is
// a PNG, and there is no silent wrong answer: wherever the reported link or force is wrong, a
// flag of estimates.csv says so (docs/log_format.md, docs/estimator.md), judged against the
// truth columns of the original log. The shared robots are skipped when ../shared is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "support/build_info.hpp"
#include "support/scratch_dir.hpp"
#include "support/text_files.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

using test::read_text;
using test::write_text;

const fs::path kScenarios = fs::path(EXTWRENCH_TEST_DATA_DIR) / "new_user";
const fs::path kShared = fs::path(EXTWRENCH_SHARED_DIR) / "models";

struct Robot {
  std::string name;      ///< test name
  fs::path file;         ///< the robot file as the user has it
  std::string options;   ///< what the user adds on the command line (--package-path, --lock)
  std::string config;    ///< extra lines of the user's estimator configuration
  int joints = 0;        ///< n after locking
  std::string scenario;  ///< tests/data/new_user/<scenario>
};

// gtest prints a parameter with this (not as the bytes of the struct).
void PrintTo(const Robot& robot, std::ostream* os) {
  *os << robot.name << " (" << robot.file << ")";
}

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

std::vector<Robot> robots() {
  const fs::path panda = kShared / "franka_panda/urdf_example-robot-data";
  const fs::path ur5 = kShared / "ur5/urdf_example-robot-data";
  return {
      {"Panda", panda / "urdf/panda.urdf", "--package-path " + quoted(panda),
       "locked_joints: {panda_finger_joint1: 0.02, panda_finger_joint2: 0.02}\n", 7, "panda.yaml"},
      {"UR5", ur5 / "urdf/ur5_robot.urdf", "--package-path " + quoted(ur5), "", 6, "ur5.yaml"},
      {"PaperArm", fs::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf", "", "", 7,
       "paper_arm.yaml"},
  };
}

bool contains(const std::string& text, const std::string& needle) {
  return text.find(needle) != std::string::npos;
}

// A CSV file as cells (the files written by extwrench have no quoted cells: link names and flag
// lists hold no comma).
struct Table {
  std::map<std::string, std::size_t> column;
  std::vector<std::vector<std::string>> rows;

  static Table read(const fs::path& path) {
    Table t;
    std::istringstream in(read_text(path));
    std::string line;
    bool header = true;
    while (std::getline(in, line)) {
      std::vector<std::string> cells = test::split_cells(line);
      if (header) {
        for (std::size_t i = 0; i < cells.size(); ++i) t.column[cells[i]] = i;
        header = false;
      } else {
        t.rows.push_back(std::move(cells));
      }
    }
    return t;
  }
  bool has(const std::string& name) const { return column.count(name) != 0; }
  const std::string& text(std::size_t row, const std::string& name) const {
    return rows[row].at(column.at(name));
  }
  double number(std::size_t row, const std::string& name) const {
    const std::string& s = text(row, name);
    return s.empty() ? std::nan("") : std::strtod(s.c_str(), nullptr);
  }
};

// A PNG file: the signature, and an image header with a plausible size.
::testing::AssertionResult is_png(const fs::path& path) {
  const std::string bytes = read_text(path);
  if (bytes.size() < 1000) return ::testing::AssertionFailure() << path << ": missing or tiny";
  if (bytes.substr(0, 8) != "\x89PNG\r\n\x1a\n" || bytes.substr(12, 4) != "IHDR")
    return ::testing::AssertionFailure() << path << ": not a PNG";
  const auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  if (be32(16) < 200 || be32(20) < 200)
    return ::testing::AssertionFailure() << path << ": " << be32(16) << "x" << be32(20);
  return ::testing::AssertionSuccess();
}

// The flags that tell the user a reported link or force may be wrong (docs/estimator.md).
bool warns(const std::string& status) {
  for (const char* flag : {"disagreement", "ambiguous", "residual_isolation", "partial",
                           "unobservable", "ill_conditioned", "surface_missed"}) {
    if (contains("|" + status + "|", std::string("|") + flag + "|")) return true;
  }
  return false;
}

struct Verdict {
  int settled = 0;         ///< samples in contact with the force steady for the last 0.1 s
  int undetected = 0;      ///< settled samples without a declared contact
  int wrong = 0;           ///< settled samples with the wrong link or force (> 10 % off)
  int silent = 0;          ///< ... of which without a warning flag
  int disagreement = 0;    ///< settled samples flagged `disagreement`
  double force_rms = 0.0;  ///< ‖F̂ − F‖ over the settled samples with a force [N]
  std::string first_silent;
};

// Judges `estimates` against the truth of `log` (row by row: the estimates have one row per log
// row) on the samples where the truth is steady: the residual's transient (5/K = 50 ms at the
// default gain) is over.
Verdict judge(const Table& log, const Table& estimates) {
  Verdict v;
  EXPECT_EQ(log.rows.size(), estimates.rows.size());
  if (log.rows.size() != estimates.rows.size()) return v;
  const double sample_time = log.number(1, "t") - log.number(0, "t");
  const auto steps = static_cast<std::size_t>(std::lround(0.1 / sample_time));
  const auto force = [&](std::size_t k) {
    if (log.text(k, "true_link").empty()) return 0.0;
    return std::hypot(log.number(k, "true_fx"), log.number(k, "true_fy"), log.number(k, "true_fz"));
  };
  double sum2 = 0.0;
  int with_force = 0;
  for (std::size_t k = steps; k < log.rows.size(); ++k) {
    const double f = force(k);
    if (f < 1.0) continue;
    bool steady = true;
    for (std::size_t j = k - steps; j < k && steady; ++j) steady = std::abs(force(j) - f) < 1e-9;
    if (!steady) continue;
    ++v.settled;
    const std::string& status = estimates.text(k, "status");
    if (contains(status, "disagreement")) ++v.disagreement;
    if (estimates.text(k, "contact") != "1") {
      ++v.undetected;
      continue;
    }
    const double ex = estimates.number(k, "fx") - log.number(k, "true_fx");
    const double ey = estimates.number(k, "fy") - log.number(k, "true_fy");
    const double ez = estimates.number(k, "fz") - log.number(k, "true_fz");
    const double error = std::sqrt(ex * ex + ey * ey + ez * ez);
    if (std::isfinite(error)) {
      sum2 += error * error;
      ++with_force;
    }
    const bool wrong_link = estimates.text(k, "link") != log.text(k, "true_link");
    const bool wrong_force = !(error <= 0.1 * f);
    if (!wrong_link && !wrong_force) continue;
    ++v.wrong;
    if (warns(status)) continue;
    if (v.silent++ == 0) {
      v.first_silent = "t = " + log.text(k, "t") + ": link '" + estimates.text(k, "link") +
                       "' (true '" + log.text(k, "true_link") + "'), force error " +
                       std::to_string(error) + " N of " + std::to_string(f) + " N, status '" +
                       status + "'";
    }
  }
  v.force_rms = with_force > 0 ? std::sqrt(sum2 / with_force) : std::nan("");
  return v;
}

const std::vector<std::string> kSensorTypes{"ft", "force", "none"};
const std::vector<std::string> kFigures{"joints",    "force",    "line_point",
                                        "condition", "residual", "robot3d"};

class NewUser : public test::ScratchDirTest, public ::testing::WithParamInterface<Robot> {
 protected:
  NewUser() : ScratchDirTest("extwrench_new_user") {}

  test::CliResult run(const std::string& args) const {
    return test::run_cli(EXTWRENCH_CLI, args, dir_);
  }
};

TEST_P(NewUser, InfoDynamicsSimulateAndEstimateOnALogWithoutTruthGiveNoSilentWrongAnswer) {
  const Robot& robot = GetParam();
  if (!fs::exists(robot.file)) GTEST_SKIP() << "shared models absent: " << robot.file;
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "gnuplot not installed (the figures are part of the acceptance)";
  // About 20 s per robot in the optimised build; the sanitizer build runs the same code paths in
  // the other CLI tests.
  if (test::kSanitizerBuild) GTEST_SKIP() << "long: runs in the optimised build";

  // info: a serial chain of the expected joints (the Panda's fingers locked).
  const test::CliResult info = run("info " + quoted(robot.file) + " " + robot.options +
                                   (robot.name == "Panda" ? " --lock panda_finger_joint1=0.02 "
                                                            "--lock panda_finger_joint2=0.02"
                                                          : ""));
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_TRUE(contains(info.out, "joints: " + std::to_string(robot.joints) + ", serial chain"))
      << info.out;
  const auto mass_at = info.out.find("total mass: ");
  ASSERT_NE(mass_at, std::string::npos) << info.out;
  const double total_mass = std::strtod(info.out.c_str() + mass_at + 12, nullptr);

  // dynamics: at rest the sensor reads the robot's weight (every one of these sensors is aligned
  // with the root frame); in motion it runs through.
  const int n = robot.joints;
  std::string states = "t";
  for (const char* group : {"q", "dq", "ddq"})
    for (int i = 1; i <= n; ++i) states += "," + std::string(group) + std::to_string(i);
  states += "\n";
  for (int row = 0; row < 3; ++row) {
    states += std::to_string(0.001 * row);
    for (int i = 0; i < 3 * n; ++i) states += row == 0 ? ",0" : ",0.3";
    states += "\n";
  }
  write_text(dir_ / "states.csv", states);
  const std::string lock_config =
      robot.name == "Panda" ? " --lock panda_finger_joint1=0.02 --lock panda_finger_joint2=0.02"
                            : "";
  const test::CliResult dyn =
      run("dynamics --robot " + quoted(robot.file) + " " + robot.options + lock_config + " --in " +
          quoted(dir_ / "states.csv") + " --out " + quoted(dir_ / "predicted.csv"));
  ASSERT_EQ(dyn.code, 0) << dyn.err;
  const Table predicted = Table::read(dir_ / "predicted.csv");
  ASSERT_EQ(predicted.rows.size(), 3u);
  EXPECT_NEAR(predicted.number(0, "fs_z"), -total_mass * 9.81, 1e-3 * total_mass);
  EXPECT_NEAR(predicted.number(0, "fs_x"), 0.0, 1e-9);

  // simulate: 3 seeds, every scheme, every figure.
  const fs::path sim = dir_ / "sim";
  const test::CliResult s = run("simulate " + quoted(kScenarios / robot.scenario) + " " +
                                robot.options + " --jobs 2 --out " + quoted(sim));
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_TRUE(is_png(sim / "summary.png"));
  // The scenarios set no singularity window: its columns say so instead of showing zeros.
  EXPECT_FALSE(contains(s.out, "excludes ±0 s")) << s.out;
  EXPECT_FALSE(contains(read_text(sim / "summary.gp"), "outside singularity"));  // nor its legend
  std::istringstream table(s.out);
  for (std::string line; std::getline(table, line);) {
    std::istringstream words(line);
    std::string scheme, seed, f_rms, f_rms_outside;
    words >> scheme >> seed >> f_rms >> f_rms_outside;
    if (seed == "worst") {
      EXPECT_EQ(f_rms_outside, "-") << line;
    }
  }
  for (int seed = 1; seed <= 3; ++seed) {
    const fs::path sd = sim / ("seed_" + std::to_string(seed));
    ASSERT_TRUE(fs::exists(sd / "log.csv")) << sd;
    const Table log = Table::read(sd / "log.csv");
    for (const std::string& type : kSensorTypes) {
      for (const std::string& figure : kFigures) EXPECT_TRUE(is_png(sd / type / (figure + ".png")));
      const Verdict v = judge(log, Table::read(sd / type / "estimates.csv"));
      SCOPED_TRACE("simulate, seed " + std::to_string(seed) + ", " + type);
      EXPECT_GT(v.settled, 1000);
      EXPECT_EQ(v.undetected, 0);
      EXPECT_EQ(v.silent, 0) << v.silent << " of " << v.wrong << " wrong samples without a flag, "
                             << "first " << v.first_silent;
      EXPECT_LT(v.disagreement, v.settled / 10);
      if (type == "ft") {
        EXPECT_LT(v.force_rms, 1.0);  // of a 20 N push, with ±1 % model errors
      }
    }
  }
  for (const auto& e : fs::recursive_directory_iterator(sim))
    EXPECT_FALSE(contains(e.path().filename().string(), ".partial")) << e.path();

  // estimate: the user's own configuration (the robot file as given, the Panda's fingers locked
  // in it) on seed 1's log without its truth columns.
  const Table truth = Table::read(sim / "seed_1/log.csv");
  write_text(dir_ / "robot_log.csv",
             test::drop_columns(read_text(sim / "seed_1/log.csv"), {"true_"}));
  ASSERT_FALSE(contains(read_text(dir_ / "robot_log.csv"), "true_"));
  for (const std::string& type : kSensorTypes) {
    SCOPED_TRACE("estimate, " + type);
    const fs::path config = dir_ / ("config_" + type + ".yaml");
    write_text(config, "robot: " + robot.file.string() + "\n" + robot.config +
                           "sensor: {type: " + type + "}\n");
    const fs::path out = dir_ / ("est_" + type);
    const test::CliResult e =
        run("estimate --config " + quoted(config) + " --log " + quoted(dir_ / "robot_log.csv") +
            " " + robot.options + " --out " + quoted(out));
    ASSERT_EQ(e.code, 0) << e.err;
    EXPECT_FALSE(contains(e.err, "warning")) << e.err;
    for (const std::string& figure : kFigures) EXPECT_TRUE(is_png(out / (figure + ".png")));
    EXPECT_FALSE(fs::exists(out / "metrics.json")) << "no truth, no metrics";
    for (const auto& f : fs::directory_iterator(out))
      EXPECT_FALSE(contains(f.path().filename().string(), ".partial")) << f.path();
    const Table estimates = Table::read(out / "estimates.csv");
    ASSERT_TRUE(estimates.has("status"));
    const Verdict v = judge(truth, estimates);
    EXPECT_GT(v.settled, 1000);
    EXPECT_EQ(v.undetected, 0);
    EXPECT_EQ(v.silent, 0) << v.silent << " of " << v.wrong << " wrong samples without a flag, "
                           << "first " << v.first_silent;
    EXPECT_LT(v.disagreement, v.settled / 10);
    if (type == "ft") {
      EXPECT_LT(v.force_rms, 0.5);  // the estimator's model is the simulated robot's
      EXPECT_EQ(v.wrong, 0) << v.first_silent;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SharedAndPaperRobots, NewUser, ::testing::ValuesIn(robots()),
                         [](const ::testing::TestParamInfo<Robot>& p) { return p.param.name; });

}  // namespace
}  // namespace extwrench
