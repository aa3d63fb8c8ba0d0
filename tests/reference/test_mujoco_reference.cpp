// extwrench's inverse dynamics and base-sensor prediction against MuJoCo 2.2.2, which loads the
// same URDF with its own parser (our parser is not involved).
//
// Set-up, so that MuJoCo computes the rigid-body dynamics we model and nothing else:
//  - <mujoco><compiler inertiafromgeom="false" fusestatic="false" .../></mujoco> is added to a
//    copy of the URDF whose <visual>/<collision> are removed: the URDF inertials are used as
//    given, and fixed-jointed links stay separate bodies (link 0 is MuJoCo body 1, welded to the
//    world);
//  - MuJoCo 2.2.2's compiler diagonalizes each inertia tensor (body_inertia, body_iquat) with an
//    iterative solver that stops at ~1e-7 relative accuracy (measured on the Panda: link 1's
//    iyz comes back as 0.0191694570 for 0.019169), which alone moves τ by ~1e-6 N m. The
//    principal axes and moments are therefore recomputed in double precision here, from the
//    URDF's <inertial> read directly from the text (no extwrench code involved), and
//    body_sameframe is cleared so that MuJoCo uses the new principal axes;
//  - damping, armature, friction loss and joint stiffness are zeroed and the constraint solver,
//    limits, contacts and passive forces are disabled.
// MuJoCo conventions used here (MuJoCo documentation, mjdata.h):
//  - mj_inverse gives qfrc_inverse = M qacc + qfrc_bias (passive and constraint forces being
//    off): the total generalized force, without the external wrenches. Our rnea(W) is
//    τ = M q̈ + c − Σ Jᵀ W, so it is compared with qfrc_inverse − Σ Jᵀ W, the Jᵀ W from
//    mj_applyFT (MuJoCo's own Jacobian at the application point).
//  - xfrc_applied[b] = [force; torque] in world axes, the force acting at the body's CoM
//    (xipos); a force F at p plus a pure moment M becomes torque M + (p − xipos) × F.
//  - after mj_rnePostConstraint, cfrc_int[b] = [torque; force] ([angular; linear]!) that the
//    parent applies to body b, world axes, moment about subtree_com[body_rootid[b]]. For body 1
//    (link 0) that is f_0, the wrench the ground applies to the robot: the sensor reads −f_0.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Eigenvalues>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "reference/mujoco_util.hpp"
#include "reference/reference_util.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

// MuJoCo runs the same recursions in double precision; its only extra step is diagonalizing
// each body inertia (iterative, converged to ~1e-15). 1e-8 is the acceptance bound.
constexpr double kTol = 1e-8;
constexpr int kStates = 200;

const char* const kCompiler =
    "<mujoco><compiler angle=\"radian\" discardvisual=\"true\" fusestatic=\"false\" "
    "balanceinertia=\"false\" inertiafromgeom=\"false\" boundmass=\"0\" boundinertia=\"0\"/>"
    "</mujoco>";

struct RobotCase {
  const char* name;
  std::string urdf_path;
  bool shared;              ///< under EXTWRENCH_SHARED_DIR (skip when absent)
  std::string tip;          ///< truncate the URDF to root -> tip; empty keeps the whole tree
  std::string sensor_link;  ///< sensor frame from the URDF, or empty for kArbitrarySensor
};

const Pose kArbitrarySensor =
    Pose::from_xyz_rpy(Vector3(0.03, -0.02, -0.25), Vector3(0.1, -0.2, 0.3));

std::string case_path(const RobotCase& c) {
  return std::string(c.shared ? EXTWRENCH_SHARED_DIR : EXTWRENCH_SOURCE_DIR) + "/" + c.urdf_path;
}

Vector3 vec3(const mjtNum* p) { return test::mj_vec3(p); }
using test::body_pose;
using test::Worst;

class MujocoReference : public ::testing::TestWithParam<RobotCase> {
 protected:
  void SetUp() override {
    const RobotCase& c = GetParam();
    if (c.shared && !std::filesystem::exists(case_path(c))) {
      GTEST_SKIP() << "shared models absent: " << case_path(c);
    }
    const std::string full = test::read_text(case_path(c));
    test::UrdfEditOptions ours_opt;
    ours_opt.tip = c.tip;
    LoadOptions load;
    load.load_meshes = false;
    robot_ = c.tip.empty()
                 ? load_urdf(case_path(c), load)
                 : load_urdf_string(test::urdf_for_reference(full, ours_opt), c.name, load);

    test::UrdfEditOptions mj_opt = ours_opt;
    mj_opt.extra_xml = kCompiler;
    const std::string xml = test::urdf_for_reference(full, mj_opt);
    auto vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    ASSERT_EQ(mj_makeEmptyFileVFS(vfs.get(), "robot.urdf", static_cast<int>(xml.size())), 0);
    std::memcpy(vfs->filedata[0], xml.data(), xml.size());
    char error[1000] = "";
    m_.reset(mj_loadXML("robot.urdf", vfs.get(), error, sizeof(error)));
    mj_deleteVFS(vfs.get());
    ASSERT_TRUE(m_) << error;

    // Exact principal inertia (see the header comment), from the URDF text.
    const auto inertials = test::urdf_inertials(xml);
    for (int b = 1; b < m_->nbody; ++b) {
      const auto it = inertials.find(mj_id2name(m_.get(), mjOBJ_BODY, b));
      if (it == inertials.end()) continue;
      const test::UrdfInertial& u = it->second;
      ASSERT_EQ(m_->body_mass[b], u.mass);
      ASSERT_EQ(vec3(m_->body_ipos + 3 * b), u.com);
      const Matrix3 inertia_link = u.rotation * u.inertia * u.rotation.transpose();
      const Eigen::SelfAdjointEigenSolver<Matrix3> eig(inertia_link);
      Matrix3 axes = eig.eigenvectors();
      if (axes.determinant() < 0) axes.col(2) *= -1.0;
      const Eigen::Quaterniond quat(axes);
      const mjtNum iquat[4] = {quat.w(), quat.x(), quat.y(), quat.z()};
      // MuJoCo's own tensor must already be close: this only removes its round-off.
      mjtNum r[9];
      mju_quat2Mat(r, m_->body_iquat + 4 * b);
      const Matrix3 r_mj = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r);
      const Matrix3 inertia_mj =
          r_mj * vec3(m_->body_inertia + 3 * b).asDiagonal() * r_mj.transpose();
      EXPECT_LE((inertia_mj - inertia_link).norm(), 1e-5 * inertia_link.norm()) << it->first;
      for (int i = 0; i < 3; ++i) m_->body_inertia[3 * b + i] = eig.eigenvalues()[i];
      mju_copy4(m_->body_iquat + 4 * b, iquat);
      // The compiler flagged bodies whose inertial frame was the body frame (iquat = 1, ipos =
      // 0) and then ignores iquat for them: the new axes must be used.
      m_->body_sameframe[b] = 0;
    }

    // Only rigid-body dynamics: no joint damping, armature, friction, springs, constraints.
    for (int i = 0; i < m_->nv; ++i) {
      m_->dof_damping[i] = 0;
      m_->dof_armature[i] = 0;
      m_->dof_frictionloss[i] = 0;
    }
    for (int j = 0; j < m_->njnt; ++j) m_->jnt_stiffness[j] = 0;
    m_->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_EQUALITY | mjDSBL_FRICTIONLOSS |
                            mjDSBL_LIMIT | mjDSBL_CONTACT | mjDSBL_PASSIVE;
    d_.reset(mj_makeData(m_.get()));

    const Model& model = robot_.model;
    ASSERT_EQ(m_->nv, model.nq());
    ASSERT_EQ(m_->nq, model.nq());
    // Gravity is not in a URDF: both must default to the same vector.
    ASSERT_EQ(vec3(m_->opt.gravity), model.gravity);
    for (int j = 0; j < m_->njnt; ++j) {
      const auto joint = model.find_joint(mj_id2name(m_.get(), mjOBJ_JOINT, j));
      ASSERT_TRUE(joint.has_value()) << mj_id2name(m_.get(), mjOBJ_JOINT, j);
      ASSERT_EQ(m_->jnt_qposadr[j], m_->jnt_dofadr[j]);
      dof_to_q_.push_back({m_->jnt_dofadr[j], *joint - 1});
    }
    // MuJoCo body 1 must be our link 0, welded to the world.
    ASSERT_EQ(m_->body_parentid[1], 0);
    ASSERT_EQ(m_->body_jntnum[1], 0);
    ASSERT_EQ(model.body_index(mj_id2name(m_.get(), mjOBJ_BODY, 1)), 0);
    for (int b = 1; b < m_->nbody; ++b) {
      const auto frame = model.find_frame(mj_id2name(m_.get(), mjOBJ_BODY, b));
      ASSERT_TRUE(frame.has_value()) << mj_id2name(m_.get(), mjOBJ_BODY, b);
      body_frame_.push_back(*frame);  // body_frame_[b - 1]
    }
    if (!c.sensor_link.empty()) {
      mj_kinematics(m_.get(), d_.get());
      X_WS_ = body_pose(d_.get(), mj_name2id(m_.get(), mjOBJ_BODY, c.sensor_link.c_str()));
    }
  }

  void to_mujoco(const VectorX& x, mjtNum* out) const {
    for (const auto& [dof, qi] : dof_to_q_) out[dof] = x[qi];
  }
  VectorX from_mujoco(const mjtNum* in) const {
    VectorX x(robot_.model.nq());
    for (const auto& [dof, qi] : dof_to_q_) x[qi] = in[dof];
    return x;
  }

  void run(bool with_wrenches, unsigned seed);

  RobotDescription robot_;
  test::MjModelPtr m_;
  test::MjDataPtr d_;
  std::vector<std::pair<int, int>> dof_to_q_;  ///< (MuJoCo dof, our q index)
  std::vector<int> body_frame_;                ///< MuJoCo body b -> our frame body_frame_[b - 1]
  Pose X_WS_ = kArbitrarySensor;
};

void MujocoReference::run(bool with_wrenches, unsigned seed) {
  const Model& model = robot_.model;
  mjModel* m = m_.get();
  mjData* d = d_.get();
  Data data(model);
  const int n = model.nq();
  SeededRng rng(seed);
  const std::string label = std::string(GetParam().name) + (with_wrenches ? " W_ext" : "");
  Worst worst_tau{label + " tau vs mj_inverse"};
  Worst worst_base{label + " base wrench vs cfrc_int"};
  std::vector<mjtNum> jtw(static_cast<std::size_t>(m->nv));
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3.1, 3.1), dq = rng.uniform_vector(n, -2, 2),
                  ddq = rng.uniform_vector(n, -5, 5);
    to_mujoco(q, d->qpos);
    to_mujoco(dq, d->qvel);
    to_mujoco(ddq, d->qacc);
    mju_zero(d->xfrc_applied, 6 * m->nbody);
    std::fill(jtw.begin(), jtw.end(), 0.0);
    std::vector<ExternalWrench> ours;
    if (with_wrenches) {
      mj_kinematics(m, d);  // poses, xipos
      mj_comPos(m, d);      // cdof and subtree_com, used by mj_applyFT's Jacobian
      forward_kinematics(model, data, q);
      for (int w = 0; w < 3; ++w) {
        const int b = 1 + static_cast<int>(rng.uniform(0, m->nbody - 1 - 1e-9));
        // Force F at point p plus pure moment M, in the link frame.
        const Vector3 F = rng.uniform_vector3(-50, 50), p = rng.uniform_vector3(-0.3, 0.3),
                      M = w == 2 ? Vector3::Zero() : rng.uniform_vector3(-5, 5);
        // MuJoCo side, from MuJoCo's own body pose.
        const Pose X_mj = body_pose(d, b);
        const Vector3 F_W = X_mj.rotation * F, p_W = X_mj.act(p), M_W = X_mj.rotation * M;
        const Vector3 torque_com = M_W + (p_W - vec3(d->xipos + 3 * b)).cross(F_W);
        for (int i = 0; i < 3; ++i) {
          d->xfrc_applied[6 * b + i] += F_W[i];
          d->xfrc_applied[6 * b + 3 + i] += torque_com[i];
        }
        mj_applyFT(m, d, F_W.data(), M_W.data(), p_W.data(), b, jtw.data());
        // Our side, from our frame pose.
        const int frame = body_frame_[static_cast<std::size_t>(b - 1)];
        const Pose X = frame_pose(model, data, frame);
        ours.push_back({model.frames[static_cast<std::size_t>(frame)].body, X.rotation * F,
                        X.act(p), X.rotation * M});
      }
    }
    mj_inverse(m, d);
    mj_rnePostConstraint(m, d);

    const VectorX tau = rnea(model, data, q, dq, ddq, ours);
    const VectorX tau_ref = from_mujoco(d->qfrc_inverse) - from_mujoco(jtw.data());
    const double e_tau = test::relative_error(tau, tau_ref);
    worst_tau.update(e_tau);
    EXPECT_LE(e_tau, kTol) << "state " << k << "\nours " << tau.transpose() << "\nmj   "
                           << tau_ref.transpose();

    // f_0 from cfrc_int of link 0 ([torque about c; force]), moved to O_s: n_0(O_s) = n_c + (c −
    // O_s) × f.
    const Vector3 c = vec3(d->subtree_com + 3 * m->body_rootid[1]);
    const Vector3 f0 = vec3(d->cfrc_int + 6 + 3);
    const Vector3 n0 = vec3(d->cfrc_int + 6) + (c - X_WS_.translation).cross(f0);
    Vector6 reading_ref;  // f_m = −f_0, n_m = −n_0, in the sensor frame (eqs. 9–10)
    reading_ref << -(X_WS_.rotation.transpose() * f0), -(X_WS_.rotation.transpose() * n0);
    const Vector6 reading = sensor_reading(data, X_WS_);
    const double e_base = test::relative_error(reading, reading_ref);
    worst_base.update(e_base);
    EXPECT_LE(e_base, kTol) << "state " << k << "\nours " << reading.transpose() << "\nmj   "
                            << reading_ref.transpose();
  }
}

TEST_P(MujocoReference, TorquesAndBaseWrenchMatchMujocoWithoutExternalWrenches) { run(false, 201); }

TEST_P(MujocoReference, TorquesAndBaseWrenchMatchMujocoWithExternalWrenches) { run(true, 202); }

TEST_P(MujocoReference, StaticRobotDischargesItsWeightOnTheSensor) {
  // A cross-check of the cfrc_int reading itself: at rest, f_m = M g⃗ (in S).
  const Model& model = robot_.model;
  Data data(model);
  const VectorX zero = VectorX::Zero(model.nq());
  rnea(model, data, zero, zero, zero);
  mju_zero(d_->qpos, m_->nq);
  mju_zero(d_->qvel, m_->nv);
  mju_zero(d_->qacc, m_->nv);
  mju_zero(d_->xfrc_applied, 6 * m_->nbody);
  mj_inverse(m_.get(), d_.get());
  mj_rnePostConstraint(m_.get(), d_.get());
  double total_mass = 0;
  for (int b = 1; b < m_->nbody; ++b) total_mass += m_->body_mass[b];
  const Vector3 weight_S = X_WS_.rotation.transpose() * (total_mass * vec3(m_->opt.gravity));
  EXPECT_LE((sensor_reading(data, X_WS_).head<3>() - weight_S).norm(), kTol * weight_S.norm());
  EXPECT_LE((vec3(d_->cfrc_int + 9) + total_mass * vec3(m_->opt.gravity)).norm(),
            kTol * weight_S.norm());
}

INSTANTIATE_TEST_SUITE_P(
    Robots, MujocoReference,
    ::testing::Values(RobotCase{"paper_arm", "models/paper_arm.urdf", false, "", "sensor"},
                      RobotCase{"panda_chain",
                                "models/franka_panda/urdf_example-robot-data/urdf/panda.urdf", true,
                                "panda_link7", ""},
                      RobotCase{"panda_tree",
                                "models/franka_panda/urdf_example-robot-data/urdf/panda.urdf", true,
                                "", ""}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace extwrench
