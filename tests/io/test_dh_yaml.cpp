#include <gtest/gtest.h>

#include <fstream>
#include <numbers>

#include "extwrench/core/error.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "support/io_test_util.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path p =
      fs::temp_directory_path() / ("extwrench_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p;
}

struct Row {
  bool prismatic;
  double a, alpha, d, theta;
};

// A 4-joint arm with a != 0, offsets, a prismatic joint: exercises every branch.
const Row kRows[4] = {{false, 0.0, kPi / 2, 0.30, 0.1},
                      {false, 0.40, 0.0, 0.0, -0.2},
                      {true, 0.05, -kPi / 2, 0.10, 0.3},
                      {false, 0.0, kPi / 3, 0.12, 0.0}};

std::string table(const std::string& convention) {
  std::string y = "name: t\nconvention: " + convention + "\ngravity: [0, 0, -1.62]\n";
  y += "base: {name: root, mass: 1.0, com: [0, 0, 0.1], inertia: [0.01, 0, 0, 0.01, 0, "
       "0.01]}\njoints:\n";
  for (int i = 0; i < 4; ++i) {
    const Row& r = kRows[i];
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "  - name: j%d\n    type: %s\n    a: %.17g\n    alpha: %.17g\n    d: %.17g\n    "
                  "theta: %.17g\n"
                  "    link:\n      name: l%d\n      mass: %.3g\n      com: [0.02, -0.03, 0.05]\n"
                  "      inertia: [[0.02, 0.001, 0], [0.001, 0.03, 0.002], [0, 0.002, 0.025]]\n"
                  "      collision:\n        - {type: box, size: [0.1, 0.1, 0.2], xyz: [0.01, "
                  "0.02, 0.03], rpy: [0.1, 0.2, 0.3]}\n",
                  i + 1, r.prismatic ? "prismatic" : "revolute", r.a, r.alpha, r.d, r.theta, i + 1,
                  1.0 + i);
    y += buf;
  }
  return y;
}

// DH frame i of link i, in the model: frame "l<i>" or, for standard DH with a != 0, "l<i>_dh".
std::string dh_frame(const Model& m, int i) {
  const std::string n = "l" + std::to_string(i);
  return m.find_frame(n + "_dh") ? n + "_dh" : n;
}

void check_against_direct_dh(const std::string& convention) {
  const fs::path file = write_temp(convention + ".yaml", table(convention));
  const RobotDescription r = load_robot(file);
  fs::remove(file);
  const Model& m = r.model;
  ASSERT_EQ(m.nq(), 4);
  EXPECT_TRUE(m.gravity.isApprox(Vector3(0, 0, -1.62)));
  test::SeededRng rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    const VectorX q = rng.uniform_vector(4, -2.0, 2.0);
    const auto X = test::body_poses(m, q);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int i = 1; i <= 4; ++i) {
      const Row& row = kRows[i - 1];
      const double theta = row.theta + (row.prismatic ? 0.0 : q[i - 1]);
      const double d = row.d + (row.prismatic ? q[i - 1] : 0.0);
      T = T * (convention == "standard" ? test::dh_standard(row.a, row.alpha, d, theta)
                                        : test::dh_modified(row.a, row.alpha, d, theta));
      const Pose X_dh = test::world_frame_pose(m, X, dh_frame(m, i));
      EXPECT_TRUE(test::near(X_dh, T, 1e-12)) << convention << " frame " << i;
      // Mass properties were given in the DH frame: the world CoM must agree.
      const Inertia& in = m.bodies[static_cast<std::size_t>(i)].inertia;
      const Vector3 com_W = X[static_cast<std::size_t>(i)].act(in.com);
      EXPECT_LT((com_W - T * Eigen::Vector3d(0.02, -0.03, 0.05)).norm(), 1e-12)
          << convention << " link " << i;
      Matrix3 I_dh;
      I_dh << 0.02, 0.001, 0, 0.001, 0.03, 0.002, 0, 0.002, 0.025;
      const Matrix3 I_W = X[static_cast<std::size_t>(i)].rotation * in.inertia_com *
                          X[static_cast<std::size_t>(i)].rotation.transpose();
      EXPECT_LT((I_W - T.linear() * I_dh * T.linear().transpose()).cwiseAbs().maxCoeff(), 1e-12);
      // Collision shapes too.
      const CollisionShape& s = r.geometry.shapes[static_cast<std::size_t>(
          r.geometry.body_shapes[static_cast<std::size_t>(i)][0])];
      const Pose X_shape = X[static_cast<std::size_t>(i)] * s.placement;
      EXPECT_TRUE(test::near(
          X_shape,
          T * test::iso(Pose::from_xyz_rpy(Vector3(0.01, 0.02, 0.03), Vector3(0.1, 0.2, 0.3))),
          1e-12));
    }
  }
}

TEST(DhYaml, StandardConventionMatchesTheDhProductIncludingOffsetsPrismaticAndNonzeroA) {
  check_against_direct_dh("standard");
}

TEST(DhYaml, ModifiedConventionMatchesCraigsProduct) { check_against_direct_dh("modified"); }

TEST(DhYaml, StandardDhWithNonzeroAAddsANamedDhFrame) {
  const fs::path file = write_temp("a.yaml", table("standard"));
  const Model m = load_robot(file).model;
  fs::remove(file);
  EXPECT_FALSE(m.find_frame("l1_dh")) << "a = 0: the link frame is the DH frame";
  EXPECT_TRUE(m.find_frame("l2_dh"));
  EXPECT_EQ(m.body_index("l2_dh"), 2);
}

TEST(DhYaml, PiExpressionsCustomDhFrameNamesAndGravityOverride) {
  const std::string y = R"(name: pi
convention: standard
base: {mass: 0}
joints:
  - {name: j1, type: revolute, a: 0.5, alpha: -pi/2, d: 0, theta: 2*pi/3, lower: -pi, upper: 0.5*pi,
     link: {name: l1, mass: 1, com: [0, 0, 0], inertia: [0.1, 0, 0, 0.1, 0, 0.1], dh_frame: elbow}}
frames:
  - {name: tool, link: l1, xyz: [0, 0, 0.1], rpy: [0, 0, pi]}
)";
  const fs::path file = write_temp("pi.yaml", y);
  LoadOptions o;
  o.gravity = Vector3(1, 2, 3);
  const Model m = load_robot(file, o).model;
  fs::remove(file);
  EXPECT_TRUE(m.gravity.isApprox(Vector3(1, 2, 3)));
  EXPECT_EQ(m.bodies[0].name, "link0") << "default base name";
  EXPECT_DOUBLE_EQ(m.joints[1].lower, -kPi);
  EXPECT_DOUBLE_EQ(m.joints[1].upper, kPi / 2);
  ASSERT_TRUE(m.find_frame("elbow"));
  // Frames are given in the DH frame: tool = DH1 * Tz(0.1) Rz(pi).
  const auto X = test::body_poses(m, VectorX::Zero(1));
  const Eigen::Isometry3d dh = test::dh_standard(0.5, -kPi / 2, 0, 2 * kPi / 3);
  EXPECT_TRUE(test::near(test::world_frame_pose(m, X, "elbow"), dh, 1e-12));
  Eigen::Isometry3d tool = dh;
  tool.translate(Eigen::Vector3d(0, 0, 0.1));
  tool.rotate(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(test::near(test::world_frame_pose(m, X, "tool"), tool, 1e-12));
}

}  // namespace
}  // namespace extwrench
