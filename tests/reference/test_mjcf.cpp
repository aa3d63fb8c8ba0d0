// The MJCF reader (bridges/mujoco) against MuJoCo itself: the same file compiled by
// mj_loadXML here, independently of the reader, and simulated by MuJoCo.
//  - inverse dynamics: our rnea on the converted Model against mj_inverse (qfrc_inverse =
//    M qacc + qfrc_bias with armature on M's diagonal, as ours), passive forces, limits,
//    contacts and constraints disabled; with external wrenches through xfrc_applied and
//    mj_applyFT (test_mujoco_reference.cpp explains the conventions);
//  - the base wrench: our sensor_reading against cfrc_int of the root body (the wrench the world
//    applies to it, [torque about subtree_com; force]) and, where the file has them, MuJoCo's
//    <force>/<torque> sensors at the site `sensor` (which read −reading_S: MuJoCo reports the
//    wrench the child body applies to the parent... measured below, docs/mujoco.md);
//  - kinematics: every MuJoCo body's frame, site and collision geom against ours.
// Our world frame is the root body's frame: MuJoCo's world poses are mapped through X_{W,root}.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "reference/mujoco_util.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::mj_pose;
using test::mj_vec3;
using test::SeededRng;
using test::Worst;

constexpr double kTol = 1e-8;  // the acceptance bound (issue 13)
constexpr int kStates = 200;

struct MjcfCase {
  const char* name;
  std::string path;  ///< relative to the source tree, or to ../shared when `shared`
  bool shared;
  std::vector<std::string> locked;  ///< joints locked at 0 (ours) and held at 0 (MuJoCo)
};

void PrintTo(const MjcfCase& c, std::ostream* os) { *os << c.name; }

// mj_id2name, "" for an unnamed object (its null would crash a std::string_view).
const char* name_of(const mjModel* m, int type, int id) {
  const char* name = mj_id2name(m, type, id);
  return name != nullptr ? name : "";
}

std::string case_path(const MjcfCase& c) {
  return std::string(c.shared ? EXTWRENCH_SHARED_DIR : EXTWRENCH_SOURCE_DIR) + "/" + c.path;
}

class MjcfReference : public ::testing::TestWithParam<MjcfCase> {
 protected:
  void SetUp() override {
    const MjcfCase& c = GetParam();
    if (c.shared && !std::filesystem::exists(case_path(c)))
      GTEST_SKIP() << "shared models absent: " << case_path(c);
    LoadOptions load;
    for (const std::string& joint : c.locked) load.locked_joints[joint] = 0.0;
    robot_ = mujoco::load_mjcf(case_path(c), load);

    char error[1000] = "";
    m_.reset(mj_loadXML(case_path(c).c_str(), nullptr, error, sizeof error));
    ASSERT_TRUE(m_) << error;
    m_->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_EQUALITY | mjDSBL_FRICTIONLOSS |
                            mjDSBL_LIMIT | mjDSBL_CONTACT | mjDSBL_PASSIVE;
    d_.reset(mj_makeData(m_.get()));
    mj_kinematics(m_.get(), d_.get());

    const Model& model = robot_.model;
    root_ = mj_name2id(m_.get(), mjOBJ_BODY, model.bodies[0].name.c_str());
    ASSERT_GT(root_, 0) << model.bodies[0].name;
    X_root_W_ = test::body_pose(d_.get(), root_).inverse();
    for (int j = 0; j < m_->njnt; ++j) {
      const auto joint = model.find_joint(name_of(m_.get(), mjOBJ_JOINT, j));
      if (!joint) continue;  // another body of the scene, or a locked joint
      dof_to_q_.push_back({m_->jnt_dofadr[j], *joint - 1});
      qpos_to_q_.push_back({m_->jnt_qposadr[j], *joint - 1});
    }
    ASSERT_EQ(static_cast<int>(dof_to_q_.size()), model.nq());
    for (int b = 1; b < m_->nbody; ++b) {
      if (model.find_frame(name_of(m_.get(), mjOBJ_BODY, b))) robot_bodies_.push_back(b);
    }
    const int site = mj_name2id(m_.get(), mjOBJ_SITE, "sensor");
    X_WS_ = site < 0 ? Pose::identity()
                     : X_root_W_ * mj_pose(d_->site_xpos + 3 * site, d_->site_xmat + 9 * site);
    force_sensor_ = mj_name2id(m_.get(), mjOBJ_SENSOR, "base_force");
    torque_sensor_ = mj_name2id(m_.get(), mjOBJ_SENSOR, "base_torque");
  }

  void to_mujoco(const VectorX& x, mjtNum* out) const {
    mju_zero(out, m_->nv);
    for (const auto& [dof, qi] : dof_to_q_) out[dof] = x[qi];
  }
  VectorX from_mujoco(const mjtNum* in) const {
    VectorX x(robot_.model.nq());
    for (const auto& [dof, qi] : dof_to_q_) x[qi] = in[dof];
    return x;
  }
  // qpos of the robot's joints; the other joints (locked, other bodies) stay at qpos0.
  void set_qpos(const VectorX& q) const {
    mju_copy(d_->qpos, m_->qpos0, m_->nq);
    for (const auto& [adr, qi] : qpos_to_q_) d_->qpos[adr] = q[qi];
  }

  void run(bool with_wrenches, unsigned seed);
  void add_wrenches(SeededRng& rng, const VectorX& q, std::vector<ExternalWrench>& ours,
                    std::vector<mjtNum>& jtw);

  RobotDescription robot_;
  test::MjModelPtr m_;
  test::MjDataPtr d_;
  int root_ = -1;
  Pose X_root_W_;
  Pose X_WS_;
  int force_sensor_ = -1, torque_sensor_ = -1;
  std::vector<std::pair<int, int>> dof_to_q_;   ///< (MuJoCo dof, our q index)
  std::vector<std::pair<int, int>> qpos_to_q_;  ///< (MuJoCo qpos address, our q index)
  std::vector<int> robot_bodies_;               ///< MuJoCo bodies that are frames of ours
};

// Three random wrenches (force at a point plus a pure moment) on random bodies of the robot,
// applied on both sides: xfrc_applied and its Jᵀ W (mj_applyFT) for MuJoCo, ExternalWrench here.
void MjcfReference::add_wrenches(SeededRng& rng, const VectorX& q,
                                 std::vector<ExternalWrench>& ours, std::vector<mjtNum>& jtw) {
  const Model& model = robot_.model;
  Data data(model);
  mj_kinematics(m_.get(), d_.get());
  mj_comPos(m_.get(), d_.get());
  forward_kinematics(model, data, q);
  for (int w = 0; w < 3; ++w) {
    const int b = robot_bodies_[static_cast<std::size_t>(
        rng.uniform(0, static_cast<double>(robot_bodies_.size()) - 1e-9))];
    const Vector3 F = rng.uniform_vector3(-50, 50), p = rng.uniform_vector3(-0.3, 0.3),
                  M = rng.uniform_vector3(-5, 5);
    const Pose X_mj = test::body_pose(d_.get(), b);
    const Vector3 F_W = X_mj.rotation * F, p_W = X_mj.act(p), M_W = X_mj.rotation * M;
    const Vector3 torque_com = M_W + (p_W - mj_vec3(d_->xipos + 3 * b)).cross(F_W);
    for (int i = 0; i < 3; ++i) {
      d_->xfrc_applied[6 * b + i] += F_W[i];
      d_->xfrc_applied[6 * b + 3 + i] += torque_com[i];
    }
    mj_applyFT(m_.get(), d_.get(), F_W.data(), M_W.data(), p_W.data(), b, jtw.data());
    const int frame = model.frame_index(name_of(m_.get(), mjOBJ_BODY, b));
    const Pose X = frame_pose(model, data, frame);
    ours.push_back({model.frames[static_cast<std::size_t>(frame)].body, X.rotation * F, X.act(p),
                    X.rotation * M});
  }
}

void MjcfReference::run(bool with_wrenches, unsigned seed) {
  const Model& model = robot_.model;
  mjModel* m = m_.get();
  mjData* d = d_.get();
  Data data(model);
  SeededRng rng(seed);
  const std::string label = std::string(GetParam().name) + (with_wrenches ? " W_ext" : "");
  Worst worst_tau{label + " tau vs mj_inverse"};
  Worst worst_base{label + " base wrench vs cfrc_int"};
  const bool has_sensor = force_sensor_ >= 0 && torque_sensor_ >= 0;
  std::optional<Worst> worst_sensor;
  if (has_sensor) {
    worst_sensor.emplace();
    worst_sensor->what = label + " base wrench vs <force>/<torque>";
  }
  Worst worst_pose{label + " body and site poses"};
  std::vector<mjtNum> jtw(static_cast<std::size_t>(m->nv));
  for (int k = 0; k < kStates; ++k) {
    const int n = model.nq();
    const VectorX q = rng.uniform_vector(n, -3.1, 3.1), dq = rng.uniform_vector(n, -2, 2),
                  ddq = rng.uniform_vector(n, -5, 5);
    set_qpos(q);
    to_mujoco(dq, d->qvel);
    to_mujoco(ddq, d->qacc);
    mju_zero(d->xfrc_applied, 6 * m->nbody);
    std::fill(jtw.begin(), jtw.end(), 0.0);
    std::vector<ExternalWrench> ours;
    if (with_wrenches) add_wrenches(rng, q, ours, jtw);
    mj_inverse(m, d);
    mj_rnePostConstraint(m, d);
    mj_sensorAcc(m, d);

    const VectorX tau = rnea(model, data, q, dq, ddq, ours);
    const VectorX tau_ref = from_mujoco(d->qfrc_inverse) - from_mujoco(jtw.data());
    worst_tau.update(test::relative_error(tau, tau_ref));
    EXPECT_LE(test::relative_error(tau, tau_ref), kTol)
        << "state " << k << "\nours " << tau.transpose() << "\nmj   " << tau_ref.transpose();

    // cfrc_int of the root: the world's wrench on the robot; the sensor reads its opposite in S.
    const Vector3 c_W = mj_vec3(d->subtree_com + 3 * m->body_rootid[root_]);
    const Vector3 f0_W = mj_vec3(d->cfrc_int + 6 * root_ + 3);
    const Pose X_WS_mj = X_root_W_.inverse() * X_WS_;
    const Vector3 n0_W = mj_vec3(d->cfrc_int + 6 * root_) + (c_W - X_WS_mj.translation).cross(f0_W);
    Vector6 reading_ref;
    reading_ref << -(X_WS_mj.rotation.transpose() * f0_W), -(X_WS_mj.rotation.transpose() * n0_W);
    const Vector6 reading = sensor_reading(data, X_WS_);
    worst_base.update(test::relative_error(reading, reading_ref));
    EXPECT_LE(test::relative_error(reading, reading_ref), kTol)
        << "state " << k << "\nours " << reading.transpose() << "\nmj   "
        << reading_ref.transpose();
    if (has_sensor) {
      Vector6 sensed;
      sensed << -mj_vec3(d->sensordata + m->sensor_adr[force_sensor_]),
          -mj_vec3(d->sensordata + m->sensor_adr[torque_sensor_]);
      worst_sensor->update(test::relative_error(reading, sensed));
      EXPECT_LE(test::relative_error(reading, sensed), kTol)
          << "state " << k << "\nours " << reading.transpose() << "\nmj   " << sensed.transpose();
    }
    // Every MuJoCo body and site of the robot where ours is (mj_inverse ran mj_kinematics; rnea
    // forms no pose).
    forward_poses(model, data, q);
    for (std::size_t f = 0; f < model.frames.size(); ++f) {
      const char* name = model.frames[f].name.c_str();
      const int b = mj_name2id(m, mjOBJ_BODY, name), s = mj_name2id(m, mjOBJ_SITE, name);
      if (b < 0 && s < 0) continue;  // an anchor link
      const Pose X_ref = X_root_W_ * (b >= 0 ? test::body_pose(d, b)
                                             : mj_pose(d->site_xpos + 3 * s, d->site_xmat + 9 * s));
      const Pose X = frame_pose(model, data, static_cast<int>(f));
      const double e = std::max((X.translation - X_ref.translation).norm(),
                                (X.rotation - X_ref.rotation).norm());
      worst_pose.update(e);
      EXPECT_LE(e, kTol) << name << " state " << k;
    }
  }
}

TEST_P(MjcfReference, TorquesBaseWrenchAndFramesMatchMujocoWithoutExternalWrenches) {
  run(false, 1301);
}

TEST_P(MjcfReference, TorquesBaseWrenchAndFramesMatchMujocoWithExternalWrenches) {
  run(true, 1302);
}

TEST_P(MjcfReference, JointParametersAreMujocosCompiledOnes) {
  const Model& model = robot_.model;
  for (const auto& [dof, qi] : dof_to_q_) {
    const Joint& joint = model.joints[static_cast<std::size_t>(qi + 1)];
    const int j = m_->dof_jntid[dof];
    EXPECT_EQ(joint.damping, m_->dof_damping[dof]) << joint.name;
    EXPECT_EQ(joint.friction, m_->dof_frictionloss[dof]) << joint.name;
    EXPECT_EQ(joint.armature, m_->dof_armature[dof]) << joint.name;
    EXPECT_EQ(joint.type == JointType::kPrismatic, m_->jnt_type[j] == mjJNT_SLIDE) << joint.name;
    if (m_->jnt_limited[j]) {
      EXPECT_EQ(joint.lower, m_->jnt_range[2 * j]) << joint.name;
      EXPECT_EQ(joint.upper, m_->jnt_range[2 * j + 1]) << joint.name;
    } else {
      EXPECT_TRUE(std::isinf(joint.lower) && std::isinf(joint.upper)) << joint.name;
    }
  }
  double mass = 0.0;
  for (int b = 1; b < m_->nbody; ++b) {
    if (robot_.model.find_frame(name_of(m_.get(), mjOBJ_BODY, b))) mass += m_->body_mass[b];
  }
  EXPECT_NEAR(model.total_mass(), mass, 1e-12 * mass);
}

// The distance from p to the capsule's segment (z axis, half-length h, of its frame).
double distance_to_segment(const Vector3& p_G, double h) {
  const double z = std::clamp(p_G.z(), -h, h);
  return (p_G - Vector3(0, 0, z)).norm();
}

// Each collision geom of MuJoCo where our shape is, at random states: same pose and size; an
// ellipsoid inside its capsule; mesh vertices where MuJoCo puts them.
TEST_P(MjcfReference, CollisionShapesSitOnMujocosGeoms) {
  const Model& model = robot_.model;
  const GeometryModel& geometry = robot_.geometry;
  std::vector<int> geoms;  // MuJoCo's collision geoms of the robot, in our order
  for (int g = 0; g < m_->ngeom; ++g) {
    const bool robot_body = std::find(robot_bodies_.begin(), robot_bodies_.end(),
                                      m_->geom_bodyid[g]) != robot_bodies_.end() ||
                            m_->geom_bodyid[g] == root_;
    if (robot_body && (m_->geom_contype[g] != 0 || m_->geom_conaffinity[g] != 0))
      geoms.push_back(g);
  }
  ASSERT_EQ(geoms.size(), geometry.shapes.size());
  Data data(model);
  SeededRng rng(1303);
  Worst worst{std::string(GetParam().name) + " collision shape poses"};
  for (int k = 0; k < 20; ++k) {
    const VectorX q = rng.uniform_vector(model.nq(), -3.1, 3.1);
    set_qpos(q);
    mj_kinematics(m_.get(), d_.get());
    forward_kinematics(model, data, q);
    for (std::size_t i = 0; i < geoms.size(); ++i) {
      const int g = geoms[i];
      const CollisionShape& shape = geometry.shapes[i];
      const Pose X_WG = frame_pose(model, data, model.frame_index(model.bodies[shape.body].name)) *
                        shape.placement;
      const Pose X_WG_mj = X_root_W_ * mj_pose(d_->geom_xpos + 3 * g, d_->geom_xmat + 9 * g);
      const Vector3 size = mj_vec3(m_->geom_size + 3 * g);
      if (m_->geom_type[g] == mjGEOM_ELLIPSOID) {
        ASSERT_EQ(shape.type, ShapeType::kCapsule);
        for (int p = 0; p < 200; ++p) {  // random points of the ellipsoid's surface
          const Vector3 dir = rng.uniform_vector3(-1, 1).normalized();
          const Vector3 p_W = X_WG_mj.act(size.cwiseProduct(dir));
          EXPECT_LE(distance_to_segment(X_WG.inverse().act(p_W), shape.length / 2),
                    shape.radius + 1e-12);
        }
        continue;
      }
      const double e = std::max((X_WG.translation - X_WG_mj.translation).norm(),
                                (X_WG.rotation - X_WG_mj.rotation).norm());
      worst.update(e);
      EXPECT_LE(e, kTol) << "geom " << g;
      switch (m_->geom_type[g]) {
        case mjGEOM_SPHERE:
          EXPECT_EQ(shape.type, ShapeType::kSphere);
          EXPECT_EQ(shape.radius, size[0]);
          break;
        case mjGEOM_CAPSULE:
        case mjGEOM_CYLINDER:
          EXPECT_EQ(shape.type, m_->geom_type[g] == mjGEOM_CAPSULE ? ShapeType::kCapsule
                                                                   : ShapeType::kCylinder);
          EXPECT_EQ(shape.radius, size[0]);
          EXPECT_EQ(shape.length, 2 * size[1]);
          break;
        case mjGEOM_BOX:
          EXPECT_EQ(shape.type, ShapeType::kBox);
          EXPECT_EQ(shape.size, 2 * size);
          break;
        case mjGEOM_MESH: {
          ASSERT_EQ(shape.type, ShapeType::kMesh);
          const int mesh = m_->geom_dataid[g];
          ASSERT_EQ(shape.mesh->vertices.cols(), m_->mesh_vertnum[mesh]);
          ASSERT_EQ(shape.mesh->triangles.cols(), m_->mesh_facenum[mesh]);
          break;
        }
        default:
          ADD_FAILURE() << "geom type " << m_->geom_type[g];
      }
    }
  }
}

TEST(MjcfMesh, VerticesComeBackWhereTheFileWroteThem) {
  // MuJoCo recentres a mesh on its centroid and principal axes and moves the geom to
  // compensate: in the body frame the vertices are the file's.
  const RobotDescription robot =
      mujoco::load_mjcf(std::string(EXTWRENCH_SOURCE_DIR) + "/tests/data/mjcf/features.xml");
  const Model& model = robot.model;
  const int frame = model.frame_index("slider");
  const Pose X_body_frame = model.frames[static_cast<std::size_t>(frame)].placement;
  const std::vector<Vector3> written = {
      {0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0.1}};  // the <mesh vertex> of features.xml
  int meshes = 0;
  for (const CollisionShape& shape : robot.geometry.shapes) {
    if (shape.type != ShapeType::kMesh) continue;
    ++meshes;
    ASSERT_EQ(shape.mesh->vertices.cols(), 4);
    for (Eigen::Index v = 0; v < 4; ++v) {
      const Vector3 p =
          X_body_frame.inverse().act(shape.placement.act(shape.mesh->vertices.col(v)));
      double nearest = 1.0;
      for (const Vector3& w : written) nearest = std::min(nearest, (p - w).norm());
      EXPECT_LE(nearest, 1e-6) << p.transpose();  // float vertices
    }
    ASSERT_NE(shape.mesh->ray_caster, nullptr);
  }
  EXPECT_EQ(meshes, 1);
}

TEST(MjcfTwin, PaperArmXmlHasTheDynamicsOfPaperArmUrdf) {
  // models/paper_arm.xml is the URDF's twin: same torques and base reading, up to MuJoCo 2.2.2's
  // diagonalisation of the inertia tensors (~1e-7 relative, test_mujoco_reference.cpp).
  const std::string models = std::string(EXTWRENCH_SOURCE_DIR) + "/models/";
  const RobotDescription mjcf = mujoco::load_mjcf(models + "paper_arm.xml");
  const RobotDescription urdf = load_robot(models + "paper_arm.urdf");
  ASSERT_EQ(mjcf.model.nq(), urdf.model.nq());
  ASSERT_EQ(mjcf.geometry.shapes.size(), urdf.geometry.shapes.size());
  // The sensor frame is on link 0, whose frame is the world frame.
  const Pose X_WS =
      urdf.model.frames[static_cast<std::size_t>(urdf.model.frame_index("sensor"))].placement;
  Data data_mjcf(mjcf.model), data_urdf(urdf.model);
  SeededRng rng(1304);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(7, -3.1, 3.1), dq = rng.uniform_vector(7, -2, 2),
                  ddq = rng.uniform_vector(7, -5, 5);
    const VectorX tau_mjcf = rnea(mjcf.model, data_mjcf, q, dq, ddq);
    const VectorX tau_urdf = rnea(urdf.model, data_urdf, q, dq, ddq);
    EXPECT_LE(test::relative_error(tau_mjcf, tau_urdf), 1e-6) << "state " << k;
    EXPECT_LE(
        test::relative_error(sensor_reading(data_mjcf, X_WS), sensor_reading(data_urdf, X_WS)),
        1e-6)
        << "state " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Robots, MjcfReference,
    ::testing::Values(
        MjcfCase{"paper_arm", "models/paper_arm.xml", false, {}},
        MjcfCase{"features", "tests/data/mjcf/features.xml", false, {}},
        MjcfCase{"panda_nohand",
                 "models/franka_panda/mjcf_menagerie/derived/panda_nohand_collision_only_mj222.xml",
                 true,
                 {}},
        MjcfCase{"panda_hand_locked",
                 "models/franka_panda/mjcf_menagerie/derived/panda_collision_only_mj222.xml",
                 true,
                 {"finger_joint1", "finger_joint2"}},
        MjcfCase{"iiwa14", "models/kuka_iiwa14/mjcf_menagerie/derived/iiwa14_mj222.xml", true, {}}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace extwrench
