// extwrench's dynamics against Orocos KDL 1.5, on chains that KDL builds by itself: kdl_parser
// reads the URDF (our parser is not involved), or KDL::Frame::DH is fed the paper's table
// (docs/method.md#the-papers-experiment).
//
// KDL conventions used here (checked in the KDL 1.5 sources/headers):
//  - ChainIdSolver_RNE(chain, g): g is the gravity vector in the chain's base frame; f_ext has
//    one Wrench per segment, expressed in that segment's (tip) frame, about its origin, and is
//    the wrench the environment applies to the segment (it is subtracted from I a + v x* I v).
//  - Segment frames from kdl_parser are the URDF link frames; a fixed joint gives a segment
//    without a joint coordinate. kdl_parser drops the root link's inertia, so a massless root is
//    prepended and link 0 becomes an ordinary fixed segment.
//  - ChainJntToJacSolver::JntToJac(q, J, s): Jacobian of the tip frame of the first s segments,
//    reference point at that frame's origin, base-frame axes, rows [linear; angular].
//  - The base wrench is not an output of KDL: it is measured by six virtual joints (x, y, z
//    translations, then x, y, z rotations, all at the sensor frame, massless) inserted between
//    the ground and link 0, held at q = dq = ddq = 0. Their torques are the components of the
//    wrench the ground transmits to link 0, in the sensor frame, moment about O_s: f_0 = −(f_m,
//    n_m).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/tree.hpp>
#include <kdl/treeidsolver_recursive_newton_euler.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <string>
#include <vector>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "reference/reference_util.hpp"
#include "support/random.hpp"
#include "support/test_robots.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

// Two independent double-precision implementations of the same recursions: they differ by
// round-off only (~1e-14 relative here); 1e-9 leaves room without hiding any modelling error.
constexpr double kTol = 1e-9;
// g(q) needs no velocity terms: ours and KDL's differ by a few ulps of the torques.
constexpr double kGravityTol = 1e-12;
constexpr int kStates = 200;
const char* const kWorld = "kdl_world";

double rel_err(const MatrixX& ours, const MatrixX& ref) { return test::relative_error(ours, ref); }

KDL::Frame to_kdl(const Pose& X) {
  const Matrix3& r = X.rotation;
  return {KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1),
                        r(2, 2)),
          KDL::Vector(X.translation.x(), X.translation.y(), X.translation.z())};
}

Pose from_kdl(const KDL::Frame& f) {
  Pose X;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) X.rotation(i, j) = f.M(i, j);
    X.translation[i] = f.p[i];
  }
  return X;
}

KDL::Vector to_kdl(const Vector3& v) { return {v.x(), v.y(), v.z()}; }

/// Worst errors seen over a test, printed for the record.
struct Worst {
  std::string what;
  double value = 0.0;
  void update(double e) { value = std::max(value, e); }
  ~Worst() { std::printf("[ worst    ] %-48s %.3e\n", what.c_str(), value); }
};

/// A robot as extwrench loads it and as KDL builds it, with the joint-order map between them.
struct Reference {
  RobotDescription robot;
  KDL::Tree tree;
  KDL::Chain chain;          ///< kdl_world -> tip: link 0 (fixed, with its inertia), links 1..n
  KDL::Chain sensor_chain;   ///< ground -> sensor -> 6 virtual joints -> link 0 -> ... -> tip
  Pose X_WS;                 ///< sensor pose in the root frame
  std::vector<int> q_index;  ///< KDL joint k is our q[q_index[k]]
  std::vector<int> segment_frame;  ///< chain segment s is our frame segment_frame[s]
  MatrixX P;                       ///< x_kdl = P x_ours

  int n() const { return static_cast<int>(q_index.size()); }
  KDL::JntArray to_kdl_q(const VectorX& x) const {
    KDL::JntArray out(static_cast<unsigned>(n()));
    out.data = P * x;
    return out;
  }
};

struct RobotCase {
  const char* name;
  std::string urdf_path;  ///< relative to the source or shared directory
  bool shared;            ///< under EXTWRENCH_SHARED_DIR (skip when absent)
  std::string tip;        ///< chain tip; the URDF is truncated to root -> tip when `truncate`
  bool truncate;
  std::string sensor_link;  ///< sensor frame from the URDF, or empty for kArbitrarySensor
  bool dh = false;          ///< a DH YAML, compared with the paper's table through KDL::Frame::DH
};

const Pose kArbitrarySensor =
    Pose::from_xyz_rpy(Vector3(0.03, -0.02, -0.25), Vector3(0.1, -0.2, 0.3));

std::string case_path(const RobotCase& c) {
  return std::string(c.shared ? EXTWRENCH_SHARED_DIR : EXTWRENCH_SOURCE_DIR) + "/" + c.urdf_path;
}

void build_urdf_reference(const RobotCase& c, const LoadOptions& load, Reference& ref) {
  const std::string full = test::read_text(case_path(c));
  test::UrdfEditOptions ours_opt;
  if (c.truncate) ours_opt.tip = c.tip;
  // Our parser reads the file itself, or the truncated text when the chain is a sub-tree.
  ref.robot = c.truncate ? load_urdf_string(test::urdf_for_reference(full, ours_opt), c.name, load)
                         : load_urdf(case_path(c), load);
  test::UrdfEditOptions kdl_opt = ours_opt;
  kdl_opt.new_root = kWorld;
  ASSERT_TRUE(kdl_parser::treeFromString(test::urdf_for_reference(full, kdl_opt), ref.tree));
  ASSERT_TRUE(ref.tree.getChain(kWorld, c.tip, ref.chain));

  if (c.sensor_link.empty()) {
    ref.X_WS = kArbitrarySensor;
  } else {
    KDL::Chain to_sensor;
    ASSERT_TRUE(ref.tree.getChain(kWorld, c.sensor_link, to_sensor));
    KDL::ChainFkSolverPos_recursive fk(to_sensor);
    KDL::Frame f;
    KDL::JntArray zero(to_sensor.getNrOfJoints());
    ASSERT_GE(fk.JntToCart(zero, f), 0);
    ref.X_WS = from_kdl(f);
  }
}

// The paper's arm (docs/method.md#the-papers-experiment), typed in from the table (not from
// models/): standard DH, theta_i = q_i, a_i = 0; CoM in cm and barycentric inertia in g m^2, in DH
// frame i.
struct SpecLink {
  double alpha, d, mass;
  std::array<double, 3> com_cm;
  std::array<double, 6> inertia_gm2;  // Ixx, Ixy, Ixz, Iyy, Iyz, Izz
};
const double kHalfPi = std::acos(0.0);
const std::array<SpecLink, 7> kSpecTable{{
    {kHalfPi, 0.0, 2.7, {0.1340, -8.7777, 2.6220}, {16.341, 0.003, 0.001, 5.026, -3.533, 16.173}},
    {-kHalfPi, 0.0, 2.7, {0.1340, 2.6220, 8.7777}, {16.341, 0.001, 0.003, 16.173, 3.533, 5.026}},
    {-kHalfPi, 0.40, 2.7, {0.1340, 8.7777, 2.6220}, {16.341, 0.003, 0.001, 5.026, 3.533, 16.173}},
    {kHalfPi, 0.0, 2.7, {0.1340, 2.6220, 8.7777}, {16.341, 0.001, 0.003, 16.173, 3.533, 5.026}},
    {kHalfPi, 0.39, 2.7, {0.1340, -8.7777, 2.6220}, {16.341, 0.003, 0.001, 5.026, -3.533, 16.173}},
    {-kHalfPi, 0.0, 1.7, {0.0, 0.5, 0.0}, {5.0, 0, 0, 3.6, 0, 4.7}},
    {0.0, 0.078, 0.3, {0.0, 0.0, -2.0}, {1.0, 0, 0, 1.0, 0, 1.0}},
}};

KDL::RigidBodyInertia spec_inertia(double mass, const std::array<double, 3>& com_m,
                                   const std::array<double, 6>& i_kgm2) {
  // KDL::RotationalInertia(Ixx, Iyy, Izz, Ixy, Ixz, Iyz), about the CoM here.
  return KDL::RigidBodyInertia(
      mass, KDL::Vector(com_m[0], com_m[1], com_m[2]),
      KDL::RotationalInertia(i_kgm2[0], i_kgm2[3], i_kgm2[5], i_kgm2[1], i_kgm2[2], i_kgm2[4]));
}

/// The paper's arm as KDL segments: link 0 (m0 = 2 kg, CoM 0.15 m above O_s = 0.16 m below
/// O_0, inertia diag(20, 20, 10) g m^2), then KDL::Frame::DH(a, alpha, d, theta) per joint.
KDL::Chain spec_dh_chain() {
  KDL::Chain chain;
  chain.addSegment(KDL::Segment("link0", KDL::Joint(KDL::Joint::Fixed), KDL::Frame::Identity(),
                                spec_inertia(2.0, {0, 0, -0.16}, {0.020, 0, 0, 0.020, 0, 0.010})));
  for (std::size_t i = 0; i < kSpecTable.size(); ++i) {
    const SpecLink& l = kSpecTable[i];
    std::array<double, 3> com_m{};
    std::array<double, 6> i_kgm2{};
    for (int k = 0; k < 3; ++k) com_m[k] = 0.01 * l.com_cm[k];
    for (int k = 0; k < 6; ++k) i_kgm2[k] = 1e-3 * l.inertia_gm2[k];
    const std::string n = std::to_string(i + 1);
    chain.addSegment(KDL::Segment("link" + n, KDL::Joint("joint" + n, KDL::Joint::RotZ),
                                  KDL::Frame::DH(0.0, l.alpha, l.d, 0.0),
                                  spec_inertia(l.mass, com_m, i_kgm2)));
  }
  return chain;
}

void build_reference(const RobotCase& c, Reference& ref) {
  LoadOptions load;
  load.load_meshes = false;
  if (c.dh) {
    ref.robot = load_robot(case_path(c), load);
    ref.chain = spec_dh_chain();
    ref.X_WS = Pose::from_xyz_rpy(Vector3(0, 0, -0.31), Vector3::Zero());  // O_0 = O_s + 0.31 z
  } else {
    build_urdf_reference(c, load, ref);
  }
  if (::testing::Test::HasFatalFailure()) return;
  const Model& model = ref.robot.model;

  const KDL::Frame X_WS = to_kdl(ref.X_WS);
  ref.sensor_chain.addSegment(KDL::Segment("ref_to_sensor", KDL::Joint(KDL::Joint::Fixed), X_WS));
  for (auto type : {KDL::Joint::TransX, KDL::Joint::TransY, KDL::Joint::TransZ, KDL::Joint::RotX,
                    KDL::Joint::RotY, KDL::Joint::RotZ}) {
    ref.sensor_chain.addSegment(KDL::Segment("ref_virtual", KDL::Joint("ref_virtual", type)));
  }
  ref.sensor_chain.addSegment(
      KDL::Segment("ref_from_sensor", KDL::Joint(KDL::Joint::Fixed), X_WS.Inverse()));
  ref.sensor_chain.addChain(ref.chain);

  for (unsigned s = 0; s < ref.chain.getNrOfSegments(); ++s) {
    const KDL::Segment& seg = ref.chain.getSegment(s);
    const auto frame = model.find_frame(seg.getName());
    ASSERT_TRUE(frame.has_value()) << seg.getName();
    ref.segment_frame.push_back(*frame);
    if (seg.getJoint().getType() == KDL::Joint::Fixed) continue;
    const auto joint = model.find_joint(seg.getJoint().getName());
    ASSERT_TRUE(joint.has_value()) << seg.getJoint().getName();
    ref.q_index.push_back(*joint - 1);
  }
  ASSERT_EQ(ref.n(), model.nq()) << "the chain must be the whole model";
  ref.P = MatrixX::Zero(ref.n(), ref.n());
  for (int k = 0; k < ref.n(); ++k) ref.P(k, ref.q_index[static_cast<std::size_t>(k)]) = 1.0;
}

class KdlReference : public ::testing::TestWithParam<RobotCase> {
 protected:
  void SetUp() override {
    if (GetParam().shared && !std::filesystem::exists(case_path(GetParam()))) {
      GTEST_SKIP() << "shared models absent: " << case_path(GetParam());
    }
    build_reference(GetParam(), ref_);
    if (HasFatalFailure()) return;
  }

  const Model& model() const { return ref_.robot.model; }
  KDL::Vector gravity() const { return to_kdl(model().gravity); }

  struct State {
    VectorX q, dq, ddq;
  };
  State random_state(SeededRng& rng) const {
    const int n = model().nq();
    return {rng.uniform_vector(n, -3.1, 3.1), rng.uniform_vector(n, -2, 2),
            rng.uniform_vector(n, -5, 5)};
  }

  Reference ref_;
};

TEST_P(KdlReference, LinkFramePosesMatchKdlForwardKinematics) {
  Data data(model());
  KDL::ChainFkSolverPos_recursive fk(ref_.chain);
  SeededRng rng(101);
  Worst worst{std::string(GetParam().name) + " link poses"};
  for (int k = 0; k < kStates; ++k) {
    const State x = random_state(rng);
    forward_kinematics(model(), data, x.q);
    const KDL::JntArray q = ref_.to_kdl_q(x.q);
    for (unsigned s = 0; s < ref_.chain.getNrOfSegments(); ++s) {
      KDL::Frame f;
      ASSERT_GE(fk.JntToCart(q, f, static_cast<int>(s + 1)), 0);
      const Pose X_ref = from_kdl(f);
      const Pose X = frame_pose(model(), data, ref_.segment_frame[s]);
      const double e =
          std::max(rel_err(X.rotation, X_ref.rotation), rel_err(X.translation, X_ref.translation));
      worst.update(e);
      EXPECT_LE(e, kTol) << ref_.chain.getSegment(s).getName();
    }
  }
}

// Torques and the base wrench, with random external wrenches on random links (link 0 included)
// when `with_wrenches`.
void check_rnea(const Reference& ref, const Model& model, bool with_wrenches, unsigned seed,
                const std::string& label) {
  Data data(model);
  const KDL::Vector g(model.gravity.x(), model.gravity.y(), model.gravity.z());
  KDL::ChainIdSolver_RNE id(ref.chain, g);
  KDL::ChainIdSolver_RNE id_sensor(ref.sensor_chain, g);
  const unsigned ns = ref.chain.getNrOfSegments();
  const int n = ref.n();
  SeededRng rng(seed);
  Worst worst_tau{label + " tau"}, worst_base{label + " base wrench (sensor frame)"};
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3.1, 3.1), dq = rng.uniform_vector(n, -2, 2),
                  ddq = rng.uniform_vector(n, -5, 5);
    KDL::Wrenches f_ext(ns, KDL::Wrench::Zero());
    std::vector<ExternalWrench> ours;
    if (with_wrenches) {
      forward_kinematics(model, data, q);
      for (int w = 0; w < 3; ++w) {
        const auto s = static_cast<unsigned>(rng.uniform(0, ns - 1e-9));
        // Force F at point p plus pure moment M, all in the link frame.
        const Vector3 F = rng.uniform_vector3(-50, 50), p = rng.uniform_vector3(-0.3, 0.3),
                      M = w == 2 ? Vector3::Zero() : rng.uniform_vector3(-5, 5);
        f_ext[s] = f_ext[s] + KDL::Wrench(to_kdl(F), to_kdl(M + p.cross(F)));
        const Frame& fr = model.frames[static_cast<std::size_t>(ref.segment_frame[s])];
        const Pose X_WL = frame_pose(model, data, ref.segment_frame[s]);
        ours.push_back({fr.body, X_WL.rotation * F, X_WL.act(p), X_WL.rotation * M});
      }
    }
    const VectorX tau = rnea(model, data, q, dq, ddq, ours);
    const Vector6 reading = sensor_reading(data, ref.X_WS);

    KDL::JntArray tau_ref(static_cast<unsigned>(n));
    ASSERT_GE(id.CartToJnt(ref.to_kdl_q(q), ref.to_kdl_q(dq), ref.to_kdl_q(ddq), f_ext, tau_ref),
              0);
    const double e_tau = rel_err(ref.P * tau, tau_ref.data);
    worst_tau.update(e_tau);
    EXPECT_LE(e_tau, kTol) << "state " << k;

    // The sensor chain: six virtual joints at zero, then the robot.
    const auto nv = static_cast<unsigned>(n + 6);
    KDL::JntArray qs(nv), dqs(nv), ddqs(nv), tau_s(nv);
    qs.data.tail(n) = ref.P * q;
    dqs.data.tail(n) = ref.P * dq;
    ddqs.data.tail(n) = ref.P * ddq;
    KDL::Wrenches f_ext_s(ref.sensor_chain.getNrOfSegments(), KDL::Wrench::Zero());
    for (unsigned s = 0; s < ns; ++s) f_ext_s[s + 8] = f_ext[s];
    ASSERT_GE(id_sensor.CartToJnt(qs, dqs, ddqs, f_ext_s, tau_s), 0);
    const Vector6 reading_ref = -tau_s.data.head<6>();  // f_m = −f_0, n_m = −n_0 (eqs. 9–10)
    const double e_base = rel_err(reading, reading_ref);
    worst_base.update(e_base);
    EXPECT_LE(e_base, kTol) << "state " << k << "\nours " << reading.transpose() << "\nkdl  "
                            << reading_ref.transpose();
    EXPECT_LE(rel_err(ref.P * tau, tau_s.data.tail(n)), kTol);
  }
}

TEST_P(KdlReference, RneaTorquesAndBaseWrenchMatchKdlWithoutExternalWrenches) {
  check_rnea(ref_, model(), false, 102, std::string(GetParam().name) + " rnea");
}

TEST_P(KdlReference, RneaTorquesAndBaseWrenchMatchKdlWithExternalWrenches) {
  check_rnea(ref_, model(), true, 103, std::string(GetParam().name) + " rnea(W_ext)");
}

TEST_P(KdlReference, MassMatrixAndMomentumMatchKdl) {
  Data data(model());
  KDL::ChainDynParam dyn(ref_.chain, gravity());
  SeededRng rng(104);
  const auto n = static_cast<unsigned>(ref_.n());
  Worst worst{std::string(GetParam().name) + " mass matrix"};
  Worst worst_p{std::string(GetParam().name) + " momentum B dq (O(n))"};
  for (int k = 0; k < kStates; ++k) {
    const State x = random_state(rng);
    KDL::JntSpaceInertiaMatrix m_ref(n);
    ASSERT_GE(dyn.JntToMass(ref_.to_kdl_q(x.q), m_ref), 0);
    const MatrixX m = crba(model(), data, x.q);
    const double e = rel_err(ref_.P * m * ref_.P.transpose(), m_ref.data);
    worst.update(e);
    EXPECT_LE(e, kTol) << "state " << k;
    momentum_terms(model(), data, x.q, x.dq);
    const VectorX p_ref = m_ref.data * ref_.to_kdl_q(x.dq).data;
    const double ep = rel_err(ref_.P * data.momentum, p_ref);
    worst_p.update(ep);
    EXPECT_LE(ep, kTol) << "state " << k;
    // The fused pass leaves the world mass properties crba_no_kinematics needs.
    momentum_and_bias_terms(model(), data, x.q, x.dq);
    EXPECT_LE(rel_err(ref_.P * data.momentum, p_ref), kTol) << "state " << k;
    const MatrixX m_fused = crba_no_kinematics(model(), data);
    EXPECT_LE(rel_err(ref_.P * m_fused * ref_.P.transpose(), m_ref.data), kTol) << "state " << k;
  }
}

// crba's fused pass (issue 15) against KDL at the tolerance its speed-up was allowed: the
// seeded states of the test above, 1e-12 relative instead of kTol.
TEST_P(KdlReference, MassMatrixMatchesKdlTo1e12) {
  Data data(model());
  KDL::ChainDynParam dyn(ref_.chain, gravity());
  SeededRng rng(104);
  const auto n = static_cast<unsigned>(ref_.n());
  Worst worst{std::string(GetParam().name) + " mass matrix (1e-12)"};
  for (int k = 0; k < kStates; ++k) {
    const State x = random_state(rng);
    KDL::JntSpaceInertiaMatrix m_ref(n);
    ASSERT_GE(dyn.JntToMass(ref_.to_kdl_q(x.q), m_ref), 0);
    const double e = rel_err(ref_.P * crba(model(), data, x.q) * ref_.P.transpose(), m_ref.data);
    worst.update(e);
    EXPECT_LE(e, 1e-12) << "state " << k;
  }
}

TEST_P(KdlReference, CoriolisTimesVelocityMatchesKdl) {
  Data data(model());
  KDL::ChainDynParam dyn(ref_.chain, gravity());
  SeededRng rng(105);
  const auto n = static_cast<unsigned>(ref_.n());
  Worst worst{std::string(GetParam().name) + " C(q,dq) dq"};
  for (int k = 0; k < kStates; ++k) {
    const State x = random_state(rng);
    KDL::JntArray c_ref(n);
    ASSERT_GE(dyn.JntToCoriolis(ref_.to_kdl_q(x.q), ref_.to_kdl_q(x.dq), c_ref), 0);
    const VectorX c_dq = coriolis_matrix(model(), data, x.q, x.dq) * x.dq;
    const VectorX bias = bias_torques(model(), data, x.q, x.dq);
    const VectorX g = gravity_torques(model(), data, x.q);
    const double e =
        std::max(rel_err(ref_.P * c_dq, c_ref.data), rel_err(ref_.P * (bias - g), c_ref.data));
    worst.update(e);
    EXPECT_LE(e, kTol) << "state " << k;
    // The fused momentum + bias pass: c(q, dq) - g(q) against KDL's C dq, and its ground
    // wrench against the one of rnea at q_ddot = 0 (that one is checked against KDL above).
    const Vector6 root_ref = [&] {
      rnea(model(), data, x.q, x.dq, VectorX::Zero(x.q.size()));
      return data.root_wrench_W;
    }();
    momentum_and_bias_terms(model(), data, x.q, x.dq);
    EXPECT_LE(rel_err(ref_.P * (data.tau - data.gravity_torque), c_ref.data), kTol)
        << "state " << k;
    EXPECT_LE(rel_err(data.root_wrench_W, root_ref), kTol) << "state " << k;
  }
}

TEST_P(KdlReference, GravityTorquesMatchKdl) {
  Data data(model());
  KDL::ChainDynParam dyn(ref_.chain, gravity());
  SeededRng rng(106);
  const auto n = static_cast<unsigned>(ref_.n());
  Worst worst{std::string(GetParam().name) + " g(q) (rnea and composite first moments)"};
  for (int k = 0; k < kStates; ++k) {
    const State x = random_state(rng);
    KDL::JntArray g_ref(n);
    ASSERT_GE(dyn.JntToGravity(ref_.to_kdl_q(x.q), g_ref), 0);
    const VectorX g = gravity_torques(model(), data, x.q);
    momentum_terms(model(), data, x.q, x.dq);
    const double e = std::max(rel_err(ref_.P * g, g_ref.data),
                              rel_err(ref_.P * data.gravity_torque, g_ref.data));
    worst.update(e);
    EXPECT_LE(e, kGravityTol) << "state " << k;
  }
}

// g(q) of random chains and trees (revolute and prismatic joints) against KDL's tree RNE at
// rest, on the URDF model_to_urdf writes (kdl_parser reads it; KDL's q_nr mapped by joint name).
TEST(KdlGravity, RandomChainsAndTreesMatchKdlTreeRneaAtRest) {
  const RandomChainOptions cases[] = {{.n = 7, .seed = 31},
                                      {.n = 6, .prismatic = true, .seed = 32},
                                      {.n = 9, .tree = true, .seed = 33},
                                      {.n = 12, .tree = true, .prismatic = true, .seed = 34}};
  for (const RandomChainOptions& o : cases) {
    const Model model = random_chain(o);
    const int n = model.nq();
    KDL::Tree tree;
    ASSERT_TRUE(kdl_parser::treeFromString(test::model_to_urdf(model), tree));
    ASSERT_EQ(tree.getNrOfJoints(), static_cast<unsigned>(n));
    KDL::TreeIdSolver_RNE solver(tree, to_kdl(model.gravity));
    std::vector<int> ours_of_kdl(static_cast<std::size_t>(n));
    for (const auto& [name, element] : tree.getSegments()) {
      const KDL::Joint& j = element.segment.getJoint();
      if (j.getType() == KDL::Joint::None) continue;
      ours_of_kdl[element.q_nr] = *model.find_joint(j.getName()) - 1;
    }
    Data data(model);
    SeededRng rng(108);
    Worst worst{"random model " + std::to_string(o.seed) + " g(q) vs KDL tree RNE"};
    const auto nk = static_cast<unsigned>(n);
    const KDL::JntArray zero(nk);
    for (int k = 0; k < kStates; ++k) {
      const VectorX q = rng.uniform_vector(n, -3.1, 3.1);
      KDL::JntArray qk(nk), tk(nk);
      for (unsigned i = 0; i < nk; ++i) qk(i) = q[ours_of_kdl[i]];
      ASSERT_GE(solver.CartToJnt(qk, zero, zero, KDL::WrenchMap{}, tk), 0);
      const VectorX& g = gravity_torques(model, data, q);
      VectorX g_ref(n);
      for (unsigned i = 0; i < nk; ++i) g_ref[ours_of_kdl[i]] = tk(i);
      const double e = rel_err(g, g_ref);
      worst.update(e);
      EXPECT_LE(e, kGravityTol) << "seed " << o.seed << " state " << k;
    }
  }
}

TEST_P(KdlReference, JacobiansAtEveryLinkOriginMatchKdl) {
  Data data(model());
  KDL::ChainJntToJacSolver jac_solver(ref_.chain);
  SeededRng rng(107);
  const auto n = static_cast<unsigned>(ref_.n());
  Matrix6X J(6, n);
  Worst worst{std::string(GetParam().name) + " link-origin Jacobians"};
  for (int k = 0; k < kStates; ++k) {
    const State x = random_state(rng);
    forward_kinematics(model(), data, x.q);
    const KDL::JntArray q = ref_.to_kdl_q(x.q);
    for (unsigned s = 0; s < ref_.chain.getNrOfSegments(); ++s) {
      KDL::Jacobian J_ref(n);
      ASSERT_GE(jac_solver.JntToJac(q, J_ref, static_cast<int>(s + 1)), 0);
      const int frame = ref_.segment_frame[s];
      const Pose X = frame_pose(model(), data, frame);
      point_jacobian(model(), data, model().frames[static_cast<std::size_t>(frame)].body,
                     X.translation, J);
      const double e = rel_err(J * ref_.P.transpose(), J_ref.data);
      worst.update(e);
      EXPECT_LE(e, kTol) << ref_.chain.getSegment(s).getName();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Robots, KdlReference,
    ::testing::Values(
        RobotCase{"paper_arm", "models/paper_arm.urdf", false, "link7", false, "sensor"},
        RobotCase{"panda_chain", "models/franka_panda/urdf_example-robot-data/urdf/panda.urdf",
                  true, "panda_link7", true, ""},
        RobotCase{"paper_arm_dh", "models/paper_arm.yaml", false, "link7", false, "", true}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace extwrench
