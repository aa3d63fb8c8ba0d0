// Locked joints and armature against references that parse their own files:
//  - the shared Panda with its fingers locked (LoadOptions::locked_joints) against KDL's tree
//    inverse dynamics (TreeIdSolver_RNE, every branch) on the same URDF whose finger joints a
//    text edit made fixed at the locked opening;
//  - armature (docs/model.md "Armature") against KDL's joint inertia (KDL::Joint's inertia
//    argument, set on the chain kdl_parser built) and MuJoCo's joint `armature` (an MJCF
//    written here as text), for RNEA and CRBA, to 1e-9.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <memory>
#include <string>
#include <vector>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "reference/reference_util.hpp"
#include "support/io_test_util.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

constexpr double kTol = 1e-9;
// g(q) has no velocity terms: ours and KDL's differ by a few ulps (relative_error, floor 1 N m).
constexpr double kGravityTol = 1e-12;

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("no '" + from + "' in the text");
  text.replace(at, from.size(), to);
  return text;
}

using test::no_meshes;

// ---- the Panda with its fingers locked -----------------------------------------------------

TEST(LockedPanda, InverseDynamicsMatchesKdlOnTheUrdfWithFixedFingers) {
  const fs::path file =
      test::shared_models() / "franka_panda/urdf_example-robot-data/urdf/panda.urdf";
  if (!fs::exists(file)) GTEST_SKIP() << "shared models absent";
  constexpr double kOpening = 0.02;  // each finger 2 cm out
  LoadOptions o = no_meshes();
  o.locked_joints = {{"panda_finger_joint1", kOpening}, {"panda_finger_joint2", kOpening}};
  const Model model = load_robot(file, o).model;
  ASSERT_EQ(model.nq(), 7);
  ASSERT_TRUE(model.is_serial_chain());

  // The same joints made fixed by hand: axis (0, ±1, 0) times the opening, in the origin.
  std::string xml = test::read_text(file.string());
  for (const char* j : {"panda_finger_joint1", "panda_finger_joint2"}) {
    xml = replaced(xml, std::string("name=\"") + j + "\" type=\"prismatic\"",
                   std::string("name=\"") + j + "\" type=\"fixed\"");
  }
  xml = replaced(xml, R"(<mimic joint="panda_finger_joint1"/>)", "");
  const std::string origin = R"(<origin rpy="0 0 0" xyz="0 0 0.0584"/>)";
  xml = replaced(xml, origin, R"(<origin rpy="0 0 0" xyz="0 0.02 0.0584"/>)");
  xml = replaced(xml, origin, R"(<origin rpy="0 0 0" xyz="0 -0.02 0.0584"/>)");
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromString(test::urdf_for_reference(xml, {}), tree));
  ASSERT_EQ(tree.getNrOfJoints(), 7u);
  const Vector3& g = model.gravity;
  KDL::TreeIdSolver_RNE solver(tree, KDL::Vector(g.x(), g.y(), g.z()));
  std::vector<int> ours_of_kdl(7);  // KDL's q_nr -> our joint coordinate
  for (const auto& [name, seg] : tree.getSegments()) {
    const KDL::Joint& j = seg.segment.getJoint();
    if (j.getType() == KDL::Joint::None) continue;
    ours_of_kdl[seg.q_nr] = *model.find_joint(j.getName()) - 1;
  }
  Data data(model);
  test::SeededRng rng(11);
  double worst = 0.0;
  double worst_gravity = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const VectorX q = rng.uniform_vector(7, -1.5, 1.5);
    const VectorX dq = rng.uniform_vector(7, -2.0, 2.0);
    const VectorX ddq = rng.uniform_vector(7, -3.0, 3.0);
    KDL::JntArray qk(7), dqk(7), ddqk(7), tk(7);
    for (int k = 0; k < 7; ++k) {
      qk(k) = q[ours_of_kdl[k]];
      dqk(k) = dq[ours_of_kdl[k]];
      ddqk(k) = ddq[ours_of_kdl[k]];
    }
    ASSERT_GE(solver.CartToJnt(qk, dqk, ddqk, KDL::WrenchMap{}, tk), 0);
    const VectorX& tau = rnea(model, data, q, dq, ddq);
    for (int k = 0; k < 7; ++k) worst = std::max(worst, std::abs(tau[ours_of_kdl[k]] - tk(k)));
    // g(q): the gravity pass on the locked model against KDL's RNE at rest.
    const KDL::JntArray zero(7);
    ASSERT_GE(solver.CartToJnt(qk, zero, zero, KDL::WrenchMap{}, tk), 0);
    VectorX g_ref(7);
    for (int k = 0; k < 7; ++k) g_ref[ours_of_kdl[k]] = tk(k);
    worst_gravity =
        std::max(worst_gravity, test::relative_error(gravity_torques(model, data, q), g_ref));
  }
  std::printf(
      "locked Panda vs KDL TreeIdSolver_RNE: max |tau| difference %.3g N m, "
      "g(q) relative difference %.3g\n",
      worst, worst_gravity);
  EXPECT_LT(worst, kTol);
  EXPECT_LT(worst_gravity, kGravityTol);
}

// ---- armature against KDL's joint inertia ---------------------------------------------------

const std::vector<double> kArmature = {0.35, 0.3, 0.12, 0.1, 0.03, 0.02, 0.01};

// The paper arm with `<dynamics armature>` on each moving joint (our extension), by text edit.
std::string paper_arm_with_armature(const std::string& xml) {
  std::string out = xml;
  for (std::size_t i = 0; i < kArmature.size(); ++i) {
    const std::string head =
        "<joint name=\"joint" + std::to_string(i + 1) + "\" type=\"revolute\">";
    out = replaced(out, head,
                   head + "<dynamics damping=\"0\" friction=\"0\" armature=\"" +
                       std::to_string(kArmature[i]) + "\"/>");
  }
  return out;
}

TEST(Armature, RneaAndMassMatrixMatchKdlJointInertia) {
  const std::string xml = test::read_text((test::project_models() / "paper_arm.urdf").string());
  const Model model =
      load_urdf_string(paper_arm_with_armature(xml), "paper_arm.urdf", no_meshes()).model;
  ASSERT_EQ(model.nq(), 7);
  for (int i = 1; i <= 7; ++i) ASSERT_EQ(model.joints[i].armature, kArmature[i - 1]);
  KDL::Tree tree;
  ASSERT_TRUE(kdl_parser::treeFromString(test::urdf_for_reference(xml, {}), tree));
  KDL::Chain parsed;
  ASSERT_TRUE(tree.getChain(model.bodies.front().name, model.bodies.back().name, parsed));
  // The same chain with each joint's inertia set (KDL adds it to τ and to H's diagonal).
  KDL::Chain chain;
  int k = 0;
  for (const KDL::Segment& s : parsed.segments) {
    const KDL::Joint& j = s.getJoint();
    if (j.getType() == KDL::Joint::None) {
      chain.addSegment(s);
      continue;
    }
    const KDL::Joint with(j.getName(), j.JointOrigin(), j.JointAxis(), j.getType(), 1.0, 0.0,
                          kArmature[static_cast<std::size_t>(k++)]);
    chain.addSegment(KDL::Segment(s.getName(), with, s.getFrameToTip(), s.getInertia()));
  }
  ASSERT_EQ(k, 7);
  const Vector3& g = model.gravity;
  KDL::ChainIdSolver_RNE id(chain, KDL::Vector(g.x(), g.y(), g.z()));
  KDL::ChainDynParam dyn(chain, KDL::Vector(g.x(), g.y(), g.z()));
  Data data(model);
  test::SeededRng rng(12);
  double worst_tau = 0.0;
  double worst_mass = 0.0;
  double worst_gravity = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const VectorX q = rng.uniform_vector(7, -2.0, 2.0);
    const VectorX dq = rng.uniform_vector(7, -2.0, 2.0);
    const VectorX ddq = rng.uniform_vector(7, -3.0, 3.0);
    KDL::JntArray qk(7), dqk(7), ddqk(7), tk(7);
    qk.data = q;
    dqk.data = dq;
    ddqk.data = ddq;
    KDL::Wrenches none(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(id.CartToJnt(qk, dqk, ddqk, none, tk), 0);
    worst_tau =
        std::max(worst_tau, (rnea(model, data, q, dq, ddq) - tk.data).cwiseAbs().maxCoeff());
    KDL::JntSpaceInertiaMatrix H(7);
    ASSERT_GE(dyn.JntToMass(qk, H), 0);
    worst_mass = std::max(worst_mass, (crba(model, data, q) - H.data).cwiseAbs().maxCoeff());
    // Armature does not enter g(q).
    KDL::JntArray gk(7);
    ASSERT_GE(dyn.JntToGravity(qk, gk), 0);
    worst_gravity =
        std::max(worst_gravity, test::relative_error(gravity_torques(model, data, q), gk.data));
  }
  std::printf("armature vs KDL joint inertia: max |tau| %.3g, max |B| %.3g, g(q) relative %.3g\n",
              worst_tau, worst_mass, worst_gravity);
  EXPECT_LT(worst_tau, kTol);
  EXPECT_LT(worst_mass, kTol);
  EXPECT_LT(worst_gravity, kGravityTol);
}

// ---- armature against MuJoCo ------------------------------------------------------------------

// Four bodies (hinge, hinge, slide, hinge) with diagonal inertias in their own axes, so that
// MuJoCo's compiler has nothing to diagonalise; both files written here.
const char* const kMjcf = R"(<mujoco><compiler angle="radian"/>
<option gravity="0 0 -9.81"/>
<worldbody>
 <body name="b1" pos="0 0 0.1"><joint name="j1" type="hinge" axis="0 0 1" armature="0.3"/>
  <inertial pos="0.02 0.01 0.1" mass="2" diaginertia="0.02 0.03 0.01"/>
  <body name="b2" pos="0 0 0.3"><joint name="j2" type="hinge" axis="0 1 0" armature="0.2"/>
   <inertial pos="0.1 0 0.02" mass="1.5" diaginertia="0.01 0.012 0.005"/>
   <body name="b3" pos="0.25 0 0"><joint name="j3" type="slide" axis="1 0 0" armature="0.5"/>
    <inertial pos="0.03 0 0" mass="0.7" diaginertia="0.002 0.003 0.004"/>
    <body name="b4" pos="0.05 0 0"><joint name="j4" type="hinge" axis="1 0 0" armature="0.05"/>
     <inertial pos="0 0.02 0" mass="0.3" diaginertia="0.001 0.0008 0.0006"/>
    </body></body></body></body>
</worldbody></mujoco>)";

const char* const kUrdf = R"(<robot name="four">
 <link name="world"/>
 <joint name="j1" type="continuous"><parent link="world"/><child link="b1"/>
  <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit effort="1" velocity="1"/>
  <dynamics armature="0.3"/></joint>
 <link name="b1"><inertial><origin xyz="0.02 0.01 0.1"/><mass value="2"/>
  <inertia ixx="0.02" iyy="0.03" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <joint name="j2" type="continuous"><parent link="b1"/><child link="b2"/>
  <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit effort="1" velocity="1"/>
  <dynamics armature="0.2"/></joint>
 <link name="b2"><inertial><origin xyz="0.1 0 0.02"/><mass value="1.5"/>
  <inertia ixx="0.01" iyy="0.012" izz="0.005" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <joint name="j3" type="prismatic"><parent link="b2"/><child link="b3"/>
  <origin xyz="0.25 0 0"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  <dynamics armature="0.5"/></joint>
 <link name="b3"><inertial><origin xyz="0.03 0 0"/><mass value="0.7"/>
  <inertia ixx="0.002" iyy="0.003" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <joint name="j4" type="continuous"><parent link="b3"/><child link="b4"/>
  <origin xyz="0.05 0 0"/><axis xyz="1 0 0"/><limit effort="1" velocity="1"/>
  <dynamics armature="0.05"/></joint>
 <link name="b4"><inertial><origin xyz="0 0.02 0"/><mass value="0.3"/>
  <inertia ixx="0.001" iyy="0.0008" izz="0.0006" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>)";

TEST(Armature, RneaAndMassMatrixMatchMujocoArmature) {
  char error[1000] = "";
  std::unique_ptr<mjVFS> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  const std::string text = kMjcf;
  ASSERT_EQ(mj_makeEmptyFileVFS(vfs.get(), "four.xml", static_cast<int>(text.size())), 0);
  std::memcpy(vfs->filedata[vfs->nfile - 1], text.data(), text.size());
  mjModel* m = mj_loadXML("four.xml", vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  ASSERT_NE(m, nullptr) << error;
  m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_PASSIVE | mjDSBL_CONTACT | mjDSBL_LIMIT;
  mjData* d = mj_makeData(m);
  const Model model = load_urdf_string(kUrdf, "four.urdf", no_meshes()).model;
  ASSERT_EQ(model.nq(), m->nv);
  Data data(model);
  test::SeededRng rng(13);
  double worst_tau = 0.0;
  double worst_mass = 0.0;
  std::vector<mjtNum> M(static_cast<std::size_t>(m->nv * m->nv));
  for (int trial = 0; trial < 50; ++trial) {
    const VectorX q = rng.uniform_vector(4, -1.0, 1.0);
    const VectorX dq = rng.uniform_vector(4, -2.0, 2.0);
    const VectorX ddq = rng.uniform_vector(4, -3.0, 3.0);
    for (int i = 0; i < 4; ++i) {
      d->qpos[i] = q[i];
      d->qvel[i] = dq[i];
      d->qacc[i] = ddq[i];
    }
    mj_inverse(m, d);  // qfrc_inverse = M qacc + qfrc_bias, M with the armature on its diagonal
    mj_fullM(m, M.data(), d->qM);
    const VectorX& tau = rnea(model, data, q, dq, ddq);
    for (int i = 0; i < 4; ++i)
      worst_tau = std::max(worst_tau, std::abs(tau[i] - d->qfrc_inverse[i]));
    const MatrixX& B = crba(model, data, q);
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c)
        worst_mass =
            std::max(worst_mass, std::abs(B(r, c) - M[static_cast<std::size_t>(4 * r + c)]));
    }
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  std::printf("armature vs MuJoCo: max |tau| %.3g, max |B| %.3g\n", worst_tau, worst_mass);
  EXPECT_LT(worst_tau, kTol);
  EXPECT_LT(worst_mass, kTol);
  // And the armature is what makes the difference: without it B's diagonal is smaller by it.
  Model bare = model;
  for (Joint& j : bare.joints) j.armature = 0.0;
  Data bare_data(bare);
  const VectorX q = VectorX::Constant(4, 0.3);
  const VectorX diff = crba(model, data, q).diagonal() - crba(bare, bare_data, q).diagonal();
  EXPECT_LT((diff - Eigen::Vector4d(0.3, 0.2, 0.5, 0.05)).cwiseAbs().maxCoeff(), 1e-15);
}

}  // namespace
}  // namespace extwrench
