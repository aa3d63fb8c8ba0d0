// ModelBuilder: URDF-like links and joints -> a validated Model (fixed joints merged,
// bodies in depth-first order), plus the physical-consistency checks of mass properties.
#include "extwrench/model/model_builder.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

#include "builder_messages.hpp"
#include "extwrench/core/error.hpp"

namespace extwrench {

namespace {

// Relative tolerance of the symmetry, positive semi-definiteness and triangle-inequality tests:
// a thin rod (I_zz = 0, I_xx = I_yy) sits exactly on the boundary and must pass after the
// rounding of a text file (about 1e-9 relative with 9-10 printed digits).
constexpr double kInertiaRelTol = 1e-8;
// Pivot of M(0) (articulated-body inertia along a joint's axis) relative to the joint's
// diagonal entry (composite inertia) below which M(0) counts as singular.
constexpr double kMassMatrixRelTol = 1e-12;
using model_detail::kMinAxisNorm;
using model_detail::num;
using model_detail::prefix;

bool finite(const Pose& x) { return x.rotation.allFinite() && x.translation.allFinite(); }

bool is_rotation(const Matrix3& r) {
  return (r.transpose() * r - Matrix3::Identity()).cwiseAbs().maxCoeff() < 1e-9 &&
         r.determinant() > 0.0;
}

const char* type_name(JointSpecType t) {
  switch (t) {
    case JointSpecType::kRevolute:
      return "revolute";
    case JointSpecType::kContinuous:
      return "continuous";
    case JointSpecType::kPrismatic:
      return "prismatic";
    case JointSpecType::kFixed:
      return "fixed";
  }
  return "unknown";
}

// Spatial inertia of a body about its own origin, in its own frame, [linear; angular] order.
Matrix6 spatial_inertia(const Inertia& in) {
  const Matrix3 Sc = skew(in.com);
  Matrix6 I6;
  I6.topLeftCorner<3, 3>() = in.mass * Matrix3::Identity();
  I6.topRightCorner<3, 3>() = -in.mass * Sc;
  I6.bottomLeftCorner<3, 3>() = in.mass * Sc;
  I6.bottomRightCorner<3, 3>() = in.inertia_com - in.mass * Sc * Sc;
  return I6;
}

// Motion transform from the parent's frame to the body's (X_PB = joint placement at q = 0):
// v_B = R^T (v_P - t x w_P), w_B = R^T w_P.
Matrix6 motion_parent_to_body(const Pose& X_PB) {
  const Matrix3 Rt = X_PB.rotation.transpose();
  Matrix6 X = Matrix6::Zero();
  X.topLeftCorner<3, 3>() = Rt;
  X.topRightCorner<3, 3>() = -Rt * skew(X_PB.translation);
  X.bottomRightCorner<3, 3>() = Rt;
  return X;
}

// Body whose joint makes M(q = 0) singular, or -1; O(n) in the number of bodies.
// M(0) is positive definite iff every pivot of its tree-ordered factorisation is positive; the
// pivots are the articulated-body inertias projected on the joint axes, D_i = S_i^T I^A_i S_i
// (leaves first, Featherstone's articulated-body recursion). D_i = 0 means the subtree below
// joint i, with the joints below it free, carries no mass or inertia along i's motion (e.g. a
// massless leaf). Each pivot is judged against its own joint's diagonal entry M_ii =
// S_i^T I^C_i S_i (composite inertia: the subtree rigid), the inertia it has when the joints
// below are locked: a long chain's tip is then as well judged as its root, where one global
// scale would grow as n^3 and reject it. Kept here (and not borrowed from dynamics/) so that
// validation does not depend on the algorithms it guards.
struct SingularJoint {
  int body = -1;       ///< -1: M(0) is positive definite
  double ratio = 0.0;  ///< D_i / M_ii (0 or NaN: nothing at all moves with the joint)
};

// Why M(0) is singular at `s`, for messages: nothing moves with the joint, or (a very long
// chain) so little against what it carries that M(0) is numerically singular.
std::string why_singular(const SingularJoint& s, const char* nothing) {
  if (!(s.ratio > 0.0)) return nothing;
  return "the links this joint moves have " + num(s.ratio) +
         " of their locked inertia about its axis with the joints below free (< " +
         num(kMassMatrixRelTol) + ": M(0) is numerically singular, condition number > " +
         num(1.0 / kMassMatrixRelTol) + ")";
}

SingularJoint singular_mass_matrix_body(const Model& model) {
  const int nb = model.num_bodies();
  if (model.nq() == 0) return {};
  std::vector<Matrix6> IA(static_cast<std::size_t>(nb));
  std::vector<Matrix6> IC(static_cast<std::size_t>(nb));
  std::vector<Vector6> S(static_cast<std::size_t>(nb), Vector6::Zero());
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    IA[ui] = IC[ui] = spatial_inertia(model.bodies[ui].inertia);
    const Joint& j = model.joints[ui];
    // The axis passes through the body's origin: a revolute joint moves it without velocity.
    if (j.type == JointType::kRevolute) {
      S[ui] << Vector3::Zero(), j.axis;
    } else {
      S[ui] << j.axis, Vector3::Zero();
    }
  }
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<std::size_t>(i);
    const Matrix6 X = motion_parent_to_body(model.joints[ui].placement);
    const Vector6 U = IA[ui] * S[ui];
    const double D = S[ui].dot(U);
    const double M_ii = S[ui].dot(IC[ui] * S[ui]);
    if (!std::isfinite(M_ii) || !(D > kMassMatrixRelTol * M_ii)) return {i, D / M_ii};
    IC[static_cast<std::size_t>(model.parents[ui])] += X.transpose() * IC[ui] * X;
    const Matrix6 Ia = IA[ui] - U * U.transpose() / D;
    IA[static_cast<std::size_t>(model.parents[ui])] += X.transpose() * Ia * X;
  }
  return {};
}

}  // namespace

void validate_inertia(const Inertia& inertia, const std::string& where) {
  const std::string p = where.empty() ? std::string() : where + ": ";
  if (!std::isfinite(inertia.mass))
    throw Error(p + "mass: expected a finite number, got " + num(inertia.mass));
  if (inertia.mass < 0.0) throw Error(p + "mass: must not be negative, got " + num(inertia.mass));
  if (!inertia.com.allFinite()) throw Error(p + "centre of mass: expected finite numbers");
  const Matrix3& I = inertia.inertia_com;
  if (!I.allFinite()) throw Error(p + "inertia: expected finite numbers");
  const double scale = I.cwiseAbs().maxCoeff();
  const char* names[3] = {"x", "y", "z"};
  for (int r = 0; r < 3; ++r) {
    for (int c = r + 1; c < 3; ++c) {
      if (std::abs(I(r, c) - I(c, r)) > kInertiaRelTol * scale) {
        throw Error(p + "inertia: not symmetric (i" + names[r] + names[c] + " = " + num(I(r, c)) +
                    ", i" + names[c] + names[r] + " = " + num(I(c, r)) + ")");
      }
    }
  }
  const Eigen::SelfAdjointEigenSolver<Matrix3> eig(0.5 * (I + I.transpose()),
                                                   Eigen::EigenvaluesOnly);
  const Vector3 l = eig.eigenvalues();  // ascending
  const std::string moments =
      "principal moments " + num(l(0)) + ", " + num(l(1)) + ", " + num(l(2));
  if (l(0) < -kInertiaRelTol * scale) {
    throw Error(p + "inertia: not positive semi-definite (" + moments + ")");
  }
  // A rigid body's principal moments satisfy I_a + I_b >= I_c (equality: planar body).
  if (l(0) + l(1) < l(2) - kInertiaRelTol * scale) {
    throw Error(p + "inertia: principal moments violate the triangle inequality (" + moments +
                ": " + num(l(0)) + " + " + num(l(1)) + " < " + num(l(2)) + ")");
  }
}

void validate_model(const Model& model) {
  const std::string p = "model '" + model.name + "': ";
  const auto nb = model.bodies.size();
  if (nb == 0) throw Error(p + "no bodies");
  if (model.joints.size() != nb || model.parents.size() != nb) {
    throw Error(p + "bodies, joints and parents differ in size (" + std::to_string(nb) + ", " +
                std::to_string(model.joints.size()) + ", " + std::to_string(model.parents.size()) +
                ")");
  }
  if (model.parents[0] != -1) throw Error(p + "parents[0] must be -1");
  if (!model.gravity.allFinite()) throw Error(p + "gravity: expected finite numbers");
  for (std::size_t i = 0; i < nb; ++i) {
    const std::string body = "body " + std::to_string(i) + " '" + model.bodies[i].name + "'";
    validate_inertia(model.bodies[i].inertia, p + body);
    if (i == 0) continue;
    if (model.parents[i] < 0 || model.parents[i] >= static_cast<int>(i)) {
      throw Error(p + body + ": parent " + std::to_string(model.parents[i]) +
                  " is not a lower index");
    }
    const Joint& j = model.joints[i];
    const std::string jn = p + "joint '" + j.name + "'";
    if (!finite(j.placement) || !is_rotation(j.placement.rotation)) {
      throw Error(jn + ": placement: expected a finite rigid transform");
    }
    if (!j.axis.allFinite() || std::abs(j.axis.norm() - 1.0) > 1e-9) {
      throw Error(jn + ": axis: expected a unit vector, got (" + num(j.axis.x()) + " " +
                  num(j.axis.y()) + " " + num(j.axis.z()) + ")");
    }
    if (std::isnan(j.lower) || std::isnan(j.upper) || j.lower > j.upper) {
      throw Error(jn + ": limits: lower " + num(j.lower) + " > upper " + num(j.upper));
    }
    if (!(j.velocity_limit >= 0.0) || !(j.effort_limit >= 0.0)) {
      throw Error(jn + ": velocity and effort limits must be non-negative");
    }
    if (!std::isfinite(j.damping) || !std::isfinite(j.friction)) {
      throw Error(jn + ": damping and friction must be finite");
    }
    if (!std::isfinite(j.armature) || j.armature < 0.0) {
      throw Error(jn + ": armature: expected a finite number >= 0, got " + num(j.armature));
    }
  }
  for (const Frame& f : model.frames) {
    if (f.body < 0 || f.body >= static_cast<int>(nb))
      throw Error(p + "frame '" + f.name + "': body out of range");
    if (!finite(f.placement))
      throw Error(p + "frame '" + f.name + "': placement: expected finite numbers");
  }
  const SingularJoint bad = singular_mass_matrix_body(model);
  if (bad.body > 0) {
    const auto ub = static_cast<std::size_t>(bad.body);
    throw Error(p + "joint '" + model.joints[ub].name + "' (body '" + model.bodies[ub].name +
                "'): the joint-space mass matrix is not positive definite at q = 0 (" +
                why_singular(bad,
                             "the bodies this joint moves carry no mass or inertia about "
                             "its axis") +
                ")");
  }
}

/// What the link and joint phases learn about the links: their indices by name, each link's
/// parent joint (-1: none) and child joints, all indices into links_ and joints_.
struct ModelBuilder::Topology {
  std::map<std::string, int, std::less<>> link_index;
  std::vector<int> parent_joint;
  std::vector<std::vector<int>> child_joints;
};

namespace {

// The Model's joint for a moving spec joint, placed in the body of its parent link.
Joint to_joint(const JointSpec& js, const Pose& X_body_parent_link) {
  Joint j;
  j.name = js.name;
  j.type = js.type == JointSpecType::kPrismatic ? JointType::kPrismatic : JointType::kRevolute;
  j.placement = X_body_parent_link * js.origin;
  j.axis = js.axis.normalized();
  if (js.type != JointSpecType::kContinuous) {
    j.lower = js.lower;
    j.upper = js.upper;
  }
  j.velocity_limit = js.velocity_limit;
  j.effort_limit = js.effort_limit;
  j.damping = js.damping;
  j.friction = js.friction;
  j.armature = js.armature;
  return j;
}

}  // namespace

// --- links: unique names, physical mass properties (in file order: the first bad link wins)
ModelBuilder::Topology ModelBuilder::index_links() const {
  Topology topology;
  std::map<std::string, int, std::less<>>& link_index = topology.link_index;
  for (std::size_t i = 0; i < links_.size(); ++i) {
    const LinkSpec& l = links_[i];
    const std::string where = prefix(l.source) + "link '" + l.name + "'";
    if (l.name.empty()) throw Error(prefix(l.source) + "link: attribute 'name': must not be empty");
    const auto [it, inserted] = link_index.emplace(l.name, static_cast<int>(i));
    if (!inserted) {
      throw Error(where + ": duplicate link name (first defined at " +
                  links_[static_cast<std::size_t>(it->second)].source + ")");
    }
    validate_inertia(l.inertia, prefix(l.inertia_source.empty() ? l.source : l.inertia_source) +
                                    "link '" + l.name + "'");
  }
  topology.parent_joint.assign(links_.size(), -1);
  topology.child_joints.resize(links_.size());
  return topology;
}

// --- joints: names, endpoints, numbers, one parent per link
void ModelBuilder::connect_joints(Topology& topology) const {
  const auto& link_index = topology.link_index;
  std::vector<int>& parent_joint = topology.parent_joint;
  std::vector<std::vector<int>>& child_joints = topology.child_joints;
  std::set<std::string, std::less<>> joint_names;
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    const JointSpec& j = joints_[k];
    const std::string where = prefix(j.source) + "joint '" + j.name + "'";
    if (j.name.empty())
      throw Error(prefix(j.source) + "joint: attribute 'name': must not be empty");
    if (!joint_names.insert(j.name).second) throw Error(where + ": duplicate joint name");
    const auto parent = link_index.find(j.parent);
    if (parent == link_index.end())
      throw Error(where + ": parent: no link named '" + j.parent + "'");
    const auto child = link_index.find(j.child);
    if (child == link_index.end()) throw Error(where + ": child: no link named '" + j.child + "'");
    if (parent->second == child->second) {
      throw Error(where + ": parent and child are the same link '" + j.child + "' (a cycle)");
    }
    int& pj = parent_joint[static_cast<std::size_t>(child->second)];
    if (pj >= 0) {
      throw Error(where + ": child: link '" + j.child + "' already has a parent joint '" +
                  joints_[static_cast<std::size_t>(pj)].name + "' (" +
                  joints_[static_cast<std::size_t>(pj)].source +
                  "); a link can have only one parent");
    }
    pj = static_cast<int>(k);
    child_joints[static_cast<std::size_t>(parent->second)].push_back(static_cast<int>(k));

    if (!finite(j.origin) || !is_rotation(j.origin.rotation)) {
      throw Error(where + ": origin: expected finite numbers");
    }
    if (j.type == JointSpecType::kFixed) continue;
    if (!j.axis.allFinite()) throw Error(where + ": axis: expected finite numbers");
    if (j.axis.norm() < kMinAxisNorm) throw Error(where + ": axis: must not be zero");
    if (std::isnan(j.lower) || std::isnan(j.upper))
      throw Error(where + ": limit: lower/upper must be numbers");
    if (j.type != JointSpecType::kContinuous && j.lower > j.upper) {
      throw Error(where + ": limit: lower " + num(j.lower) + " > upper " + num(j.upper));
    }
    if (!(j.velocity_limit >= 0.0))
      throw Error(where + ": limit: velocity must be non-negative, got " + num(j.velocity_limit));
    if (!(j.effort_limit >= 0.0))
      throw Error(where + ": limit: effort must be non-negative, got " + num(j.effort_limit));
    if (!std::isfinite(j.damping)) throw Error(where + ": dynamics: damping must be finite");
    if (!std::isfinite(j.friction)) throw Error(where + ": dynamics: friction must be finite");
    if (!std::isfinite(j.armature) || j.armature < 0.0)
      throw Error(where + ": dynamics: armature must be a finite number >= 0, got " +
                  num(j.armature));
  }
}

// The error for a link that no root reaches: every link on the way up has a parent (else it
// would be reachable from a root), so walking up from `start` closes a cycle.
std::string ModelBuilder::cycle_message(const Topology& topology, int start) const {
  const auto& link_index = topology.link_index;
  const std::vector<int>& parent_joint = topology.parent_joint;
  std::vector<int> path;
  std::vector<int> seen_at(links_.size(), -1);
  int l = start;
  while (seen_at[static_cast<std::size_t>(l)] < 0) {
    seen_at[static_cast<std::size_t>(l)] = static_cast<int>(path.size());
    path.push_back(l);
    l = link_index
            .find(
                joints_[static_cast<std::size_t>(parent_joint[static_cast<std::size_t>(l)])].parent)
            ->second;
  }
  std::string chain;
  const int first = seen_at[static_cast<std::size_t>(l)];
  for (std::size_t i = path.size(); i-- > static_cast<std::size_t>(first);) {
    chain += "'" + links_[static_cast<std::size_t>(path[i])].name + "' -> ";
  }
  chain += "'" + links_[static_cast<std::size_t>(l)].name + "'";
  const JointSpec& j = joints_[static_cast<std::size_t>(parent_joint[static_cast<std::size_t>(l)])];
  return prefix(j.source) + "joint '" + j.name + "': closes a cycle of links: " + chain;
}

// --- exactly one root, no cycles
int ModelBuilder::find_root(const Topology& topology) const {
  std::vector<int> roots;
  for (std::size_t i = 0; i < links_.size(); ++i) {
    if (topology.parent_joint[i] < 0) roots.push_back(static_cast<int>(i));
  }
  if (roots.empty()) throw Error(cycle_message(topology, 0));
  if (roots.size() > 1) {
    const LinkSpec& a = links_[static_cast<std::size_t>(roots[0])];
    const LinkSpec& b = links_[static_cast<std::size_t>(roots[1])];
    throw Error(prefix(b.source) + "link '" + b.name + "': more than one root link ('" + a.name +
                "' at " + a.source + " and '" + b.name +
                "' have no parent joint); the links must form one tree");
  }
  return roots[0];
}

// --- depth-first traversal: a moving joint starts a new body, a fixed one merges its child
Model ModelBuilder::traverse(const Topology& topology, int root,
                             std::vector<std::string>& body_source) const {
  Model model;
  model.name = name_;
  model.gravity = gravity_;
  struct Item {
    int link;
    int joint;                // joint whose child is `link`, -1 for the root
    int parent_body;          // body of the joint's parent link
    Pose X_body_parent_link;  // pose of the parent link in that body
  };
  std::vector<Item> stack{{root, -1, -1, Pose::identity()}};
  std::vector<bool> visited(links_.size(), false);
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const LinkSpec& l = links_[static_cast<std::size_t>(it.link)];
    visited[static_cast<std::size_t>(it.link)] = true;
    int body = 0;
    Pose X_body_link;
    const JointSpec* js = it.joint >= 0 ? &joints_[static_cast<std::size_t>(it.joint)] : nullptr;
    if (js == nullptr || js->type != JointSpecType::kFixed) {
      body = model.num_bodies();
      Body b;
      b.name = l.name;
      model.bodies.push_back(b);
      model.parents.push_back(it.parent_body);
      if (js != nullptr) {
        model.joints.push_back(to_joint(*js, it.X_body_parent_link));
        body_source.push_back(prefix(js->source) + "joint '" + js->name + "' (" +
                              type_name(js->type) + ") moving link '" + l.name + "'");
      } else {
        model.joints.push_back(Joint{});
        body_source.push_back(prefix(l.source) + "link '" + l.name + "'");
      }
    } else {
      body = it.parent_body;
      X_body_link = it.X_body_parent_link * js->origin;
    }
    model.frames.push_back(Frame{l.name, body, X_body_link});
    Body& b = model.bodies[static_cast<std::size_t>(body)];
    b.inertia = b.inertia + l.inertia.transformed(X_body_link);
    const auto& children = topology.child_joints[static_cast<std::size_t>(it.link)];
    for (auto c = children.rbegin(); c != children.rend(); ++c) {
      const int child =
          topology.link_index.find(joints_[static_cast<std::size_t>(*c)].child)->second;
      stack.push_back(Item{child, *c, body, X_body_link});
    }
  }
  for (std::size_t i = 0; i < links_.size(); ++i) {
    if (!visited[i]) throw Error(cycle_message(topology, static_cast<int>(i)));
  }
  return model;
}

// --- extra frames
void ModelBuilder::add_extra_frames(Model& model) const {
  for (const FrameSpec& f : frames_) {
    const std::string where = prefix(f.source) + "frame '" + f.name + "'";
    if (f.name.empty()) throw Error(prefix(f.source) + "frame: name must not be empty");
    if (model.find_frame(f.name))
      throw Error(where + ": duplicate frame name (a link or frame has it already)");
    const auto lf = model.find_frame(f.link);
    if (!lf) throw Error(where + ": link: no link or frame named '" + f.link + "'");
    if (!finite(f.placement) || !is_rotation(f.placement.rotation)) {
      throw Error(where + ": placement: expected finite numbers");
    }
    const Frame& parent = model.frames[static_cast<std::size_t>(*lf)];
    model.frames.push_back(Frame{f.name, parent.body, parent.placement * f.placement});
  }
}

// --- a massless body is fine only if M(q = 0) stays positive definite
void ModelBuilder::check_massless_bodies(const Model& model,
                                         const std::vector<std::string>& body_source) {
  const SingularJoint bad = singular_mass_matrix_body(model);
  if (bad.body > 0) {
    throw Error(body_source[static_cast<std::size_t>(bad.body)] +
                ": the joint-space mass matrix is not positive definite at q = 0: " +
                why_singular(bad,
                             "the links this joint moves carry no mass or inertia about its axis "
                             "(give the child link an <inertial>, or make the joint fixed)"));
  }
}

Model ModelBuilder::build() const {
  if (!locks_.empty()) {
    ModelBuilder reduced = *this;
    reduced.apply_locks();
    reduced.locks_.clear();
    return reduced.build();
  }
  const std::string model_where = "robot '" + name_ + "'";
  if (links_.empty()) throw Error(model_where + ": no links");
  if (links_.size() > kMaxLinks || joints_.size() > kMaxLinks) {
    throw Error(model_where + ": " + std::to_string(links_.size()) + " links and " +
                std::to_string(joints_.size()) + " joints, more than the limit of " +
                std::to_string(kMaxLinks) + " (docs/model.md)");
  }
  if (!gravity_.allFinite()) throw Error(model_where + ": gravity: expected finite numbers");
  Topology topology = index_links();
  connect_joints(topology);
  const int root = find_root(topology);
  std::vector<std::string> body_source;  // for the mass-matrix error
  Model model = traverse(topology, root, body_source);
  add_extra_frames(model);
  check_massless_bodies(model, body_source);
  validate_model(model);
  return model;
}

}  // namespace extwrench
