// Geometry-consistent isolation (estimation/isolation.hpp) without a base sensor: case E fits
// J_lᵀ x = τ̂ only on links with six joints before them. A push on the paper arm's link 4 (not
// testable) fits a force on link 6 within the tolerance, whose line may meet link 6: that choice
// must be flagged ambiguous, not reported as a clean answer (found by
// tests/system/test_new_user.cpp: 20 N on link 4 reported, unflagged, as ~9 N on link 6).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/isolation.hpp"
#include "extwrench/io/robot_loader.hpp"

namespace extwrench {
namespace {

/// The paper arm (capsules) without a base sensor: pushes and their geometric isolation.
struct PaperArmWithoutSensor {
  RobotDescription robot =
      load_robot(std::filesystem::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf");
  const Model& model = robot.model;
  Data data{robot.model};
  IsolationWorkspace ws{robot.model};
  VectorX tau_min = VectorX::Ones(robot.model.nq());
  VectorX tau_ext;

  /// τ_ext of force F_W at p_W on `link`, at the configuration of the last forward_kinematics.
  void push(int link, const Vector3& p_W, const Vector3& F_W) {
    Matrix6X J(6, model.nq());
    point_jacobian(model, data, link, p_W, J);
    tau_ext = J.topRows<3>().transpose() * F_W;
  }
  IsolationResult isolate(int residual_link) {
    const BaseWrench none{};
    IsolationInputs in;
    in.sensor = SensorType::kNone;
    in.residual_link = residual_link;
    in.tau_ext = &tau_ext;
    in.tau_min = &tau_min;
    in.base = &none;
    return isolate_on_geometry(model, data, robot.geometry, in, IsolationOptions{}, {}, ws);
  }
};

TEST(Isolation, WithoutASensorAChoiceAboveALinkThatCannotBeTestedIsFlaggedAmbiguous) {
  PaperArmWithoutSensor arm;
  const Model& model = arm.model;
  int decided = 0;
  // Configurations of the paper arm's workspace; a 20 N push normal to link 4's capsule.
  for (int k = 0; k < 20; ++k) {
    VectorX q(model.nq());
    for (int i = 0; i < model.nq(); ++i)
      q[i] = 0.9 * std::sin(1.7 * k + 2.3 * i) + (i == 3 ? 1.0 : 0.0);
    forward_kinematics(model, arm.data, q);
    const Pose& X_W4 = arm.data.X_WB[4];
    arm.push(4, X_W4.act(Vector3(0.07, 0.0, 0.1)), X_W4.rotation * Vector3(-20.0, 0.0, 0.0));
    const IsolationResult r = arm.isolate(4);
    // Links 4 and 5 have fewer than six joints before them: not testable. Whatever is chosen
    // above them is flagged; otherwise the paper's rule (link 4) stands.
    if (r.decided) {
      ++decided;
      EXPECT_GT(r.link, 5);
      EXPECT_TRUE(r.ambiguous) << "q = " << q.transpose() << ": link " << r.link;
    } else {
      EXPECT_EQ(r.link, 4);
    }
  }
  // The case of the issue: some of these configurations choose a link above.
  EXPECT_GT(decided, 0);
}

// Without a sensor a push on link 6 that leaves joint 7 at ~0 fits link 7 about as well: the
// candidates are compared on the best fit's line, and a link chosen along it that is not the
// best fit takes that fit over (`borrowed`). What it reports must be one physical wrench: its
// moment shifted to the chosen link's origin gives the same line, the entry lies on that line,
// and on the joints both links share it predicts the same torques.
TEST(Isolation, ALinkChosenAlongTheBestFitsLineReportsThatFitsWrenchAndLine) {
  PaperArmWithoutSensor arm;
  const Model& model = arm.model;
  const Data& data = arm.data;
  const IsolationWorkspace& ws = arm.ws;
  int borrowed = 0;
  for (int k = 0; k < 400; ++k) {
    VectorX q(model.nq());
    for (int i = 0; i < model.nq(); ++i) q[i] = 1.2 * std::sin(1.3 * k + 2.1 * i + 0.4);
    forward_kinematics(model, arm.data, q);
    const int link = 6 + k % 2;
    const Pose& X_WL = data.X_WB[static_cast<std::size_t>(link)];
    const double a = 0.7 * k;
    arm.push(
        link, X_WL.act(Vector3(0.07 * std::cos(a), 0.07 * std::sin(a), 0.02 * (k % 5))),
        X_WL.rotation * Vector3(-12.0 * std::cos(a), -12.0 * std::sin(a), 6.0 * std::sin(0.3 * k)));
    const IsolationResult r = arm.isolate(6);
    if (!r.decided) continue;
    const TestedCandidate& c = ws.tested[static_cast<std::size_t>(r.link)];
    if (!c.borrowed) continue;
    ++borrowed;
    const int other = r.link == 6 ? 7 : 6;  // the best fit
    const TestedCandidate& best = ws.tested[static_cast<std::size_t>(other)];
    EXPECT_EQ(c.fit.force_W, best.fit.force_W);
    const Vector3& O_l = data.X_WB[static_cast<std::size_t>(r.link)].translation;
    Vector3 p, u;
    ASSERT_TRUE(line_of_action(c.fit, O_l, p, u));
    EXPECT_LT((u - c.line_direction_W).norm(), 1e-12);
    const Vector3 w = c.line_point_W - p;
    EXPECT_LT((w - w.dot(u) * u).norm(), 1e-9) << "the shifted moment moves the line";
    const Vector3 e = c.entry.point_W - c.line_point_W;
    EXPECT_LT((e - e.dot(u) * u).norm(), 1e-9) << "the entry is not on the line";
    // Joints 1..6 are shared: the wrench on link 6 about O_6 and on link 7 about O_7 must
    // predict the same torques there.
    Matrix6X J_l(6, model.nq()), J_b(6, model.nq());
    point_jacobian(model, data, r.link, O_l, J_l);
    point_jacobian(model, data, other, data.X_WB[static_cast<std::size_t>(other)].translation, J_b);
    Vector6 w_l, w_b;
    w_l << c.fit.force_W, c.fit.moment_O;
    w_b << best.fit.force_W, best.fit.moment_O;
    const VectorX tau_l = J_l.transpose() * w_l, tau_b = J_b.transpose() * w_b;
    EXPECT_LT((tau_l.head(6) - tau_b.head(6)).cwiseAbs().maxCoeff(), 1e-9);
  }
  EXPECT_GT(borrowed, 0) << "no configuration chose a link along another candidate's line";
}

}  // namespace
}  // namespace extwrench
