// `--lock NAME=VALUE` and `--package-path` on the `extwrench` binary, run as a user would: the
// Panda (shared models) becomes a serial chain, bad locks are usage or input errors with
// messages naming them, and the tree error says what to do.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/scratch_dir.hpp"
#include "support/text_files.hpp"
namespace extwrench {
namespace {

namespace fs = std::filesystem;

const fs::path kTree = fs::path(EXTWRENCH_TEST_DATA_DIR) / "robots/gripper_tree.urdf";
const fs::path kPandaDir =
    fs::path(EXTWRENCH_SHARED_DIR) / "models/franka_panda/urdf_example-robot-data";

using RunResult = test::CliResult;
using test::read_text;

class CliLock : public test::ScratchDirTest {
 protected:
  CliLock() : ScratchDirTest("extwrench_cli_lock") {}

  RunResult run(const std::string& args) const { return test::run_cli(EXTWRENCH_CLI, args, dir_); }
};

TEST_F(CliLock, InfoOnThePandaWithLockedFingersAndItsOwnDirectoryAsPackagePath) {
  const fs::path panda = kPandaDir / "urdf/panda.urdf";
  if (!fs::exists(panda)) GTEST_SKIP() << "needs " << panda;
  const RunResult without = run("info '" + panda.string() + "'");
  EXPECT_EQ(without.code, 1);
  EXPECT_NE(without.err.find("--package-path"), std::string::npos) << without.err;
  const RunResult r = run("info '" + panda.string() + "' --package-path '" + kPandaDir.string() +
                          "' --lock panda_finger_joint1=0.02 --lock panda_finger_joint2=0.02");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("joints: 7, serial chain"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("link0.stl"), std::string::npos) << r.out;
}

TEST_F(CliLock, MalformedLocksAreUsageErrorsAndUnknownJointsInputErrors) {
  RunResult r = run("info '" + kTree.string() + "' --lock finger_slide");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--lock: expected NAME=VALUE"), std::string::npos) << r.err;
  r = run("info '" + kTree.string() + "' --lock finger_slide=abc");
  EXPECT_EQ(r.code, 2);
  r = run("info '" + kTree.string() + "' --lock finger_slide=0 --lock finger_slide=0.01");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("locked twice"), std::string::npos) << r.err;
  r = run("info '" + kTree.string() + "' --lock nope=0");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--lock nope=0: joint 'nope': no such joint"), std::string::npos) << r.err;
  r = run("dynamics --robot '" + kTree.string() + "' --lock finger_hinge=2 --in /dev/null --out -");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("outside the joint's limits [-1, 1]"), std::string::npos) << r.err;
}

TEST_F(CliLock, EstimateOnATreeSaysWhichJointsToLock) {
  std::ofstream(dir_ / "config.yaml") << "robot: " << kTree.string() << "\nsensor: {type: ft}\n";
  std::ofstream(dir_ / "log.csv") << "t,q1,q2,q3,q4,dq1,dq2,dq3,dq4,tau1,tau2,tau3,tau4\n";
  const std::string common = "estimate --config '" + (dir_ / "config.yaml").string() + "' --log '" +
                             (dir_ / "log.csv").string() + "' --out '" + (dir_ / "out").string() +
                             "' --no-figures";
  const RunResult tree = run(common);
  EXPECT_EQ(tree.code, 1);
  EXPECT_NE(tree.err.find("branch 'finger_slide', branch 'finger_hinge'"), std::string::npos)
      << tree.err;
  EXPECT_NE(tree.err.find("--lock NAME=VALUE"), std::string::npos) << tree.err;
  const RunResult locked = run(common + " --lock finger_slide=0.01 --lock finger_hinge=0");
  // The configuration now loads; the log (4 joints for a 2-joint chain) is what fails next.
  EXPECT_EQ(locked.err.find("not a serial chain"), std::string::npos) << locked.err;
  // calibrate says the same and takes --lock too (it said to, then refused the option).
  const std::string calibrate = "calibrate --config '" + (dir_ / "config.yaml").string() +
                                "' --log '" + (dir_ / "log.csv").string() + "' --out '" +
                                (dir_ / "calib.yaml").string() + "'";
  const RunResult calibrate_tree = run(calibrate);
  EXPECT_EQ(calibrate_tree.code, 1);
  EXPECT_NE(calibrate_tree.err.find("--lock NAME=VALUE"), std::string::npos) << calibrate_tree.err;
  const RunResult calibrate_locked =
      run(calibrate + " --lock finger_slide=0.01 --lock finger_hinge=0");
  EXPECT_EQ(calibrate_locked.code, 1) << calibrate_locked.err;  // the log, as above
  EXPECT_EQ(calibrate_locked.err.find("not a serial chain"), std::string::npos)
      << calibrate_locked.err;
  EXPECT_NE(calibrate_locked.err.find("log.csv"), std::string::npos) << calibrate_locked.err;
}

}  // namespace
}  // namespace extwrench
