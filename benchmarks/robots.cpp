#include "robots.hpp"

#include <cmath>
#include <filesystem>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/sample_models.hpp"
#include "reference/reference_util.hpp"
#include "support/paper_arm_table.hpp"

namespace extwrench::bench {
namespace {

// The paper's table as the tests write it, for KDL's chain: an independent copy of the numbers
// that the library's paper_arm() is built from.
using namespace test::paper_arm_table;

KDL::Chain paper_arm_chain_from_dh() {
  KDL::Chain chain;
  chain.addSegment(KDL::Segment("link0", KDL::Joint(KDL::Joint::None),
                                KDL::Frame(KDL::Vector(0, 0, kLink0Height))));
  for (int k = 0; k < 7; ++k) {
    const double* c = kInertiaGm2[k];
    // KDL: inertia in the segment's tip frame (DH frame i), rotational part about the CoM.
    const KDL::RotationalInertia I(c[0] * 1e-3, c[3] * 1e-3, c[5] * 1e-3, c[1] * 1e-3, c[2] * 1e-3,
                                   c[4] * 1e-3);
    const KDL::Vector com(kComCm[k][0] * 1e-2, kComCm[k][1] * 1e-2, kComCm[k][2] * 1e-2);
    chain.addSegment(KDL::Segment("link" + std::to_string(k + 1), KDL::Joint(KDL::Joint::RotZ),
                                  KDL::Frame::DH(0.0, kAlpha[k], kD[k], 0.0),
                                  KDL::RigidBodyInertia(kMass[k], com, I)));
  }
  return chain;
}

// One capsule per body from its origin to the next joint's origin (the flange gets the DH d_7
// segment), spheres where that length is zero; used when the robot file has no collision shapes.
GeometryModel capsules(const Model& model) {
  const double radius[8] = {0.08, 0.07, 0.07, 0.06, 0.065, 0.055, 0.06, 0.04};
  GeometryModel g;
  g.body_shapes.resize(static_cast<std::size_t>(model.num_bodies()));
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Vector3 end = b + 1 < model.num_bodies() ? model.joints[b + 1].placement.translation
                                                   : Vector3(0, 0, kD[6]);
    CollisionShape s;
    s.body = b;
    s.link = model.bodies[b].name;
    s.radius = radius[std::min(b, 7)];
    if (end.norm() > 1e-9) {
      s.type = ShapeType::kCapsule;
      s.length = end.norm();
      s.placement.rotation =
          Eigen::Quaterniond::FromTwoVectors(Vector3::UnitZ(), end.normalized()).toRotationMatrix();
      s.placement.translation = 0.5 * end;
    } else {
      s.type = ShapeType::kSphere;
    }
    g.body_shapes[b].push_back(static_cast<int>(g.shapes.size()));
    g.shapes.push_back(s);
  }
  return g;
}

bool has_shapes(const GeometryModel& g, int nb) {
  if (static_cast<int>(g.body_shapes.size()) != nb) return false;
  for (const auto& s : g.body_shapes) {
    if (s.empty()) return false;
  }
  return true;
}

PaperArm load_paper_arm() {
  PaperArm arm;
  const std::filesystem::path urdf =
      std::filesystem::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf";
  if (std::filesystem::exists(urdf)) {
    RobotDescription robot = load_urdf(urdf);
    arm.model = std::move(robot.model);
    arm.geometry = std::move(robot.geometry);
    KDL::Tree tree;
    // KDL's copy without the geometry and the root's inertia, which it does not use: urdfdom would
    // print an [ERROR] for every capsule and a [WARN] for the root's inertia at each `make bench`.
    test::UrdfEditOptions kdl_edit;
    kdl_edit.drop_root_inertial = true;
    if (!kdl_parser::treeFromString(
            test::urdf_for_reference(test::read_text(urdf.string()), kdl_edit), tree)) {
      throw std::runtime_error("kdl_parser could not read " + urdf.string());
    }
    // Tip: the deepest URDF link welded to the last body (a flange frame if there is one),
    // so that KDL's chain carries the same mass as our merged body.
    const int last = arm.model.nq();
    std::string tip = arm.model.bodies[last].name;
    for (const Frame& f : arm.model.frames) {
      if (f.body == last && tree.getSegments().count(f.name) > 0) tip = f.name;
    }
    if (!tree.getChain(tree.getRootSegment()->first, tip, arm.chain)) {
      throw std::runtime_error("KDL: no chain from the root to " + tip + " in " + urdf.string());
    }
    arm.source =
        "models/paper_arm.urdf (ours: load_urdf; KDL: kdl_parser::treeFromString on the file "
        "without its collision shapes and root inertia, which KDL does not use)";
  } else {
    arm.model = extwrench::paper_arm();
    arm.chain = paper_arm_chain_from_dh();
    arm.source = "the paper's DH table in code (ours: paper_arm(); KDL: Frame::DH)";
  }
  if (!has_shapes(arm.geometry, arm.model.num_bodies())) arm.geometry = capsules(arm.model);
  return arm;
}

void check_same_robot(const PaperArm& arm, const StatePool& pool) {
  Data data(arm.model);
  KDL::ChainIdSolver_RNE rne(
      arm.chain, KDL::Vector(arm.model.gravity.x(), arm.model.gravity.y(), arm.model.gravity.z()));
  const int n = arm.model.nq();
  if (static_cast<int>(arm.chain.getNrOfJoints()) != n) {
    throw std::runtime_error("KDL chain and model have different joint counts");
  }
  KDL::Wrenches none(arm.chain.getNrOfSegments(), KDL::Wrench::Zero());
  KDL::JntArray tau(static_cast<unsigned>(n));
  for (std::size_t k = 0; k < 16; ++k) {
    rnea(arm.model, data, pool.q[k], pool.dq[k], pool.ddq[k]);
    if (rne.CartToJnt(pool.kq[k], pool.kdq[k], pool.kddq[k], none, tau) != 0) {
      throw std::runtime_error("KDL RNE failed");
    }
    const double err = (data.tau - tau.data).cwiseAbs().maxCoeff();
    if (!(err < 1e-9 * (1.0 + tau.data.cwiseAbs().maxCoeff()))) {
      throw std::runtime_error("KDL and extwrench disagree on the paper arm's RNE by " +
                               std::to_string(err) + " N m: not the same robot");
    }
  }
}

StatePool make_state_pool(int n) {
  StatePool pool;
  std::mt19937 rng(20160927u);  // fixed seed: the same states in every run and on both sides
  auto vec = [&](double lo, double hi) {
    std::uniform_real_distribution<double> u(lo, hi);
    VectorX v(n);
    for (int i = 0; i < n; ++i) v[i] = u(rng);
    return v;
  };
  auto kdl = [&](const VectorX& v) {
    KDL::JntArray a(static_cast<unsigned>(n));
    a.data = v;
    return a;
  };
  for (std::size_t k = 0; k < StatePool::kNumStates; ++k) {
    pool.q.push_back(vec(-2.0, 2.0));
    pool.dq.push_back(vec(-1.5, 1.5));
    pool.ddq.push_back(vec(-3.0, 3.0));
    pool.tau.push_back(vec(-20.0, 20.0));
    pool.kq.push_back(kdl(pool.q.back()));
    pool.kdq.push_back(kdl(pool.dq.back()));
    pool.kddq.push_back(kdl(pool.ddq.back()));
    pool.ktau.push_back(kdl(pool.tau.back()));
  }
  return pool;
}

Trajectory make_trajectory(const Model& model, const ContactSpec& contact_spec) {
  Trajectory tr;
  tr.contact = contact_spec;
  const int n = model.nq();
  // Away from the wrist/elbow singularities (q2, q4 far from 0), so case E stays well posed;
  // inside the Panda's joint ranges too.
  const double q0[7] = {0.3, 0.8, 0.2, -1.2, 0.4, 0.9, 0.1};
  const double amp[7] = {0.4, 0.25, 0.5, 0.25, 0.6, 0.3, 0.8};
  const double freq[7] = {0.5, 1.0, 0.5, 1.0, 1.0, 0.5, 1.0};  // [Hz]: period 2 s = 2000 samples
  const double phase[7] = {0.0, 0.7, 1.4, 2.1, 2.8, 3.5, 4.2};
  if (n != 7) throw std::runtime_error("the benchmark trajectory expects a 7-DoF arm");
  Data data(model);
  const auto sensor = model.find_frame("sensor");
  for (std::size_t k = 0; k < Trajectory::kNumSamples; ++k) {
    const double t = static_cast<double>(k) * tr.dt;
    VectorX q(n), dq(n), ddq(n);
    for (int i = 0; i < n; ++i) {
      const double w = 2.0 * kPi * freq[i];
      const double arg = w * t + phase[i];
      q[i] = q0[i] + amp[i] * std::sin(arg);
      dq[i] = amp[i] * w * std::cos(arg);
      ddq[i] = -amp[i] * w * w * std::sin(arg);
    }
    forward_kinematics(model, data, q);
    if (k == 0) tr.X_WS = sensor ? frame_pose(model, data, *sensor) : Pose::identity();
    const Pose& X_WB = data.X_WB[static_cast<std::size_t>(contact_spec.body)];
    const ExternalWrench contact{contact_spec.body, X_WB.rotation * contact_spec.force_B,
                                 X_WB.act(contact_spec.point_B),
                                 X_WB.rotation * contact_spec.moment_B};
    rnea_no_kinematics(model, data, dq, ddq, std::span<const ExternalWrench>(&contact, 1));
    tr.q.push_back(q);
    tr.dq.push_back(dq);
    tr.ddq.push_back(ddq);
    tr.tau.push_back(data.tau);
    tr.ft_S.push_back(sensor_reading(data, tr.X_WS));
    KDL::JntArray a(static_cast<unsigned>(n));
    a.data = q;
    tr.kq.push_back(a);
    a.data = dq;
    tr.kdq.push_back(a);
    a.data = data.tau;
    tr.ktau.push_back(a);
  }
  return tr;
}

std::unique_ptr<MeshArm> load_panda() {
  const std::filesystem::path urdf =
      std::filesystem::path(EXTWRENCH_SHARED_DIR) /
      "models/franka_panda/urdf_example-robot-data/urdf/panda.relative.urdf";
  if (!std::filesystem::exists(urdf)) return nullptr;
  RobotDescription robot = load_urdf(urdf);
  auto arm = std::make_unique<MeshArm>();
  // Keep bodies 0..7 (link 0 to link 7 with the hand merged); the fingers come after them in
  // the depth-first order and are dropped with their frames and shapes.
  const int keep = robot.model.body_index("panda_link7") + 1;
  Model& m = robot.model;
  for (int b = keep; b < m.num_bodies(); ++b) {
    if (m.parents[static_cast<std::size_t>(b)] < keep - 1) {
      throw std::runtime_error("Panda: unexpected body order in " + urdf.string());
    }
  }
  m.bodies.resize(static_cast<std::size_t>(keep));
  m.joints.resize(static_cast<std::size_t>(keep));
  m.parents.resize(static_cast<std::size_t>(keep));
  std::erase_if(m.frames, [&](const Frame& f) { return f.body >= keep; });
  GeometryModel g;
  g.body_shapes.resize(static_cast<std::size_t>(keep));
  for (const CollisionShape& shape : robot.geometry.shapes) {
    if (shape.body >= keep) continue;
    g.body_shapes[static_cast<std::size_t>(shape.body)].push_back(
        static_cast<int>(g.shapes.size()));
    g.shapes.push_back(shape);
  }
  arm->model = std::move(m);
  arm->geometry = std::move(g);
  arm->source = "Panda (/work/shared, panda.relative.urdf, collision meshes, fingers dropped)";
  return arm;
}

/// A pushing contact on the mesh of `body`: at the vertex farthest along +x of the body frame,
/// force into the surface (−x) with a tangential part along y that loads the joint (axis z).
ContactSpec mesh_contact(const GeometryModel& geometry, int body) {
  ContactSpec c;
  c.body = body;
  double best = -1e300;
  for (int s : geometry.body_shapes.at(static_cast<std::size_t>(body))) {
    const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
    if (shape.type != ShapeType::kMesh || !shape.mesh) continue;
    for (Eigen::Index v = 0; v < shape.mesh->vertices.cols(); ++v) {
      const Vector3 p_B = shape.placement.act(shape.mesh->vertices.col(v));
      if (p_B.x() > best) {
        best = p_B.x();
        c.point_B = p_B;
      }
    }
  }
  if (best == -1e300) throw std::runtime_error("Panda: no collision mesh on the contact link");
  c.force_B = Vector3(-15.0, 30.0, 0.0);
  return c;
}

}  // namespace

const Trajectory& link6_trajectory() {
  // On link 6's capsule (radius 0.065 m, axis z), pushing inward (−x) with a tangential part
  // along z that gives joint 6 (axis −y) about 2 N m, well over the default τ_min = 1 N m.
  static const Trajectory tr =
      make_trajectory(paper_arm().model,
                      {6, Vector3(0.065, 0.0, 0.01), Vector3(-15.0, 0.0, 30.0), Vector3::Zero()});
  return tr;
}

const Trajectory& flange_trajectory() {
  static const Trajectory tr = make_trajectory(
      paper_arm().model, {7, Vector3::Zero(), Vector3(10.0, -5.0, 8.0), Vector3(0.5, 0.3, 2.5)});
  return tr;
}

const MeshArm* panda_arm() {
  static const std::unique_ptr<MeshArm> arm = load_panda();
  return arm.get();
}

const Trajectory* panda_trajectory() {
  static const std::unique_ptr<Trajectory> tr = []() -> std::unique_ptr<Trajectory> {
    const MeshArm* arm = panda_arm();
    if (arm == nullptr) return nullptr;
    return std::make_unique<Trajectory>(
        make_trajectory(arm->model, mesh_contact(arm->geometry, 6)));
  }();
  return tr.get();
}

const PaperArm& paper_arm() {
  static const PaperArm arm = [] {
    PaperArm a = load_paper_arm();
    check_same_robot(a, make_state_pool(a.model.nq()));
    return a;
  }();
  return arm;
}

const StatePool& state_pool() {
  static const StatePool pool = make_state_pool(paper_arm().model.nq());
  return pool;
}

}  // namespace extwrench::bench
