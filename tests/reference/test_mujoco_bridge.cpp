// The MuJoCo bridge (bridges/mujoco, docs/mujoco.md "The bridge") on a live simulation: the
// paper arm's MJCF twin falls under gravity onto four boxes around it, and for a while a force
// is applied to link 5 through xfrc_applied.
//  - The sample is MuJoCo's state: q = qpos, q̇ = qvel, τ = qfrc_actuator + qfrc_applied.
//  - The truth is checked against physics, not against the bridge's code: the base reading
//    MuJoCo's <force>/<torque> sensors give (the constraint solver's contact forces through
//    cfrc_int) minus our model's contact-free prediction at the same (q, q̇, q̈) is the external
//    wrench carried to the sensor (docs/conventions.md: reading = −f_0, and f_0 changes by
//    −F_ext): R_SW ΣF and R_SW Σ((p − O_s) × F + M) over the bridge's per-link truth.
//  - step() allocates nothing after set-up.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <fstream>
#include <set>
#include <string>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/bridges/mujoco.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "reference/mujoco_util.hpp"
#include "reference/reference_util.hpp"
#include "support/alloc_counter.hpp"
#include "support/scratch_dir.hpp"

namespace extwrench {
namespace {

constexpr int kSteps = 1500;  // 1.5 s at 1 kHz

class MujocoBridgeTest : public test::ScratchDirTest {
 protected:
  MujocoBridgeTest() : ScratchDirTest("mujoco_bridge") {}

  void SetUp() override {
    ScratchDirTest::SetUp();
    std::string xml = test::read_text(std::string(EXTWRENCH_SOURCE_DIR) + "/models/paper_arm.xml");
    // Four boxes around the arm (tops 0.6 m high, 0.3 m from its axis): it falls onto one.
    const std::string boxes =
        "    <geom name=\"box_px\" type=\"box\" pos=\"0.5 0 0.3\" size=\"0.2 0.6 0.3\"/>\n"
        "    <geom name=\"box_nx\" type=\"box\" pos=\"-0.5 0 0.3\" size=\"0.2 0.6 0.3\"/>\n"
        "    <geom name=\"box_py\" type=\"box\" pos=\"0 0.5 0.3\" size=\"0.3 0.2 0.3\"/>\n"
        "    <geom name=\"box_ny\" type=\"box\" pos=\"0 -0.5 0.3\" size=\"0.3 0.2 0.3\"/>\n";
    xml.insert(xml.find("<worldbody>") + std::string("<worldbody>\n").size(), boxes);
    const std::string path = (dir_ / "scene.xml").string();
    std::ofstream(path) << xml;
    robot_ = mujoco::load_mjcf(path);
    char error[1000] = "";
    m_.reset(mj_loadXML(path.c_str(), nullptr, error, sizeof error));
    ASSERT_TRUE(m_) << error;
    m_->opt.integrator = mjINT_EULER;  // mj_forward + mj_Euler is then exactly mj_step
    d_.reset(mj_makeData(m_.get()));
    d_->qpos[1] = 0.6;  // joint 2 tilted: the arm falls
    d_->qpos[3] = -0.8;
    const int site = mj_name2id(m_.get(), mjOBJ_SITE, "sensor");
    X_WS_ =
        robot_.model.frames[static_cast<std::size_t>(robot_.model.frame_index("sensor"))].placement;
    ASSERT_GE(site, 0);
  }

  RobotDescription robot_;
  test::MjModelPtr m_;
  test::MjDataPtr d_;
  Pose X_WS_;
};

TEST_F(MujocoBridgeTest, SampleIsMujocosStateAndTruthExplainsTheBaseReading) {
  mujoco::MujocoBridge bridge(m_.get(), robot_.model);
  const Model& model = robot_.model;
  Data data(model);
  const int link5 = mj_name2id(m_.get(), mjOBJ_BODY, "link5");
  std::set<int> links_touched;
  int contact_steps = 0;
  test::Worst worst_force{"bridge truth vs base reading, force"};
  test::Worst worst_moment{"bridge truth vs base reading, moment"};
  for (int k = 0; k < kSteps; ++k) {
    mju_zero(d_->xfrc_applied, 6 * m_->nbody);
    if (k >= 100 && k < 200) {
      d_->xfrc_applied[6 * link5 + 0] = 20.0;
      d_->xfrc_applied[6 * link5 + 5] = 1.5;
    }
    mju_zero(d_->ctrl, m_->nu);
    d_->ctrl[0] = 5.0 * std::sin(0.01 * k);  // the actuator torque must reach the sample
    mj_forward(m_.get(), d_.get());
    bridge.step(d_.get());
    const Sample& s = bridge.sample();
    for (int i = 0; i < model.nq(); ++i) {
      ASSERT_EQ(s.q[i], d_->qpos[i]);  // one hinge per body: qpos and dof addresses are i
      ASSERT_EQ(s.dq[i], d_->qvel[i]);
      ASSERT_EQ(s.tau[i], d_->qfrc_actuator[i] + d_->qfrc_applied[i]);
    }
    EXPECT_EQ(s.tau[0], 5.0 * std::sin(0.01 * k));

    VectorX qacc(model.nq());
    for (int i = 0; i < model.nq(); ++i) qacc[i] = d_->qacc[i];
    (void)rnea(model, data, s.q, s.dq, qacc);
    const Vector6 difference_S = s.reading_S - sensor_reading(data, X_WS_);
    Vector3 force_W = Vector3::Zero(), moment_S_W = Vector3::Zero();
    for (const auto& contact : bridge.contacts()) {
      force_W += contact.force_W;
      moment_S_W += (contact.point_W - X_WS_.translation).cross(contact.force_W) + contact.moment_W;
      if (contact.force_W.norm() > 1e-9) {
        // The pure moment left on the line of action is along the force.
        EXPECT_LE(contact.moment_W.cross(contact.force_W).norm(),
                  1e-9 * contact.force_W.squaredNorm() + 1e-12);
      }
      if (contact.body > 0) links_touched.insert(contact.body);
    }
    if (!bridge.contacts().empty() && k >= 200) ++contact_steps;
    const Vector3 force_S = X_WS_.rotation.transpose() * force_W;
    const Vector3 moment_S = X_WS_.rotation.transpose() * moment_S_W;
    const double scale = 1.0 + force_W.norm();
    worst_force.update((difference_S.head<3>() - force_S).norm() / scale);
    worst_moment.update((difference_S.tail<3>() - moment_S).norm() / scale);
    ASSERT_LE((difference_S.head<3>() - force_S).norm(), 1e-8 * scale) << "step " << k;
    ASSERT_LE((difference_S.tail<3>() - moment_S).norm(), 1e-8 * scale) << "step " << k;
    mj_Euler(m_.get(), d_.get());
  }
  // The scene did what it is for: contacts with the boxes, on links beyond link 0.
  EXPECT_GE(contact_steps, 100);
  EXPECT_FALSE(links_touched.empty());
  std::printf("[ scene    ] %d contact steps, %zu links touched\n", contact_steps,
              links_touched.size());
}

TEST_F(MujocoBridgeTest, StepAllocatesNothingAfterSetUp) {
  if (!test::allocation_counting_available()) GTEST_SKIP() << "sanitizer build";
  mujoco::BridgeOptions options;
  options.encoder_resolution = 1e-5;
  options.position_noise = 1e-4;
  options.force_noise_S = 0.1;
  mujoco::MujocoBridge bridge(m_.get(), robot_.model, options);
  std::size_t allocations = 0;
  int contact_steps = 0;
  for (int k = 0; k < kSteps; ++k) {
    mj_forward(m_.get(), d_.get());
    const test::AllocationCounter counter;
    bridge.step(d_.get());
    allocations += counter.count();
    contact_steps += bridge.contacts().empty() ? 0 : 1;
    mj_Euler(m_.get(), d_.get());
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GE(contact_steps, 100);  // contacts (per-link truth, link names) were written too
}

TEST_F(MujocoBridgeTest, EncoderResolutionAndNoiseAreApplied) {
  mujoco::BridgeOptions options;
  options.encoder_resolution = 0.01;
  mujoco::MujocoBridge bridge(m_.get(), robot_.model, options);
  mj_forward(m_.get(), d_.get());
  bridge.step(d_.get());
  EXPECT_EQ(bridge.sample().q[1], 0.6);
  EXPECT_DOUBLE_EQ(bridge.sample().q[3], -0.8);
  d_->qpos[1] = 0.6049;
  mj_forward(m_.get(), d_.get());
  bridge.step(d_.get());
  EXPECT_DOUBLE_EQ(bridge.sample().q[1], 0.6);
}

TEST_F(MujocoBridgeTest, UnknownSensorOrJointIsASetUpError) {
  mujoco::BridgeOptions options;
  options.force_sensor = "nope";
  EXPECT_THROW({ const mujoco::MujocoBridge bridge(m_.get(), robot_.model, options); }, Error);
  options.force_sensor = "base_torque";  // a torque sensor where a force one is expected
  EXPECT_THROW({ const mujoco::MujocoBridge bridge(m_.get(), robot_.model, options); }, Error);
}

}  // namespace
}  // namespace extwrench
