// Robots, geometry and a simulated arm for the observer and estimator tests. Models are built
// directly as Model structs (no parser involved); model_to_urdf writes the same robot as URDF so
// that KDL (kdl_parser + ChainIdSolver_RNE) can produce reference values with its own code.
#pragma once

#include <cmath>
#include <functional>
#include <numbers>
#include <sstream>
#include <string>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/geometry/shapes.hpp"
#include "extwrench/model/sample_models.hpp"
#include "support/random.hpp"

namespace extwrench::test {

// The estimation tests' names for the library's sample models (model/sample_models.hpp).
inline Model paper_arm_model() { return paper_arm(); }
inline Model random_model(const RandomChainOptions& options) { return random_chain(options); }

/// Capsules around the paper arm's links (radius in m): each link from its body origin to the
/// next DH origin; zero-length links are spheres.
inline GeometryModel paper_arm_capsules(const Model& model) {
  const double d[8] = {0.31, 0, 0, 0.40, 0, 0.39, 0, 0.078};
  const double radius[8] = {0.08, 0.07, 0.07, 0.06, 0.065, 0.055, 0.06, 0.04};
  GeometryModel g;
  g.body_shapes.resize(static_cast<std::size_t>(model.num_bodies()));
  for (int b = 0; b < model.num_bodies(); ++b) {
    CollisionShape s;
    s.body = b;
    s.link = model.bodies[b].name;
    s.radius = radius[b];
    if (d[b] > 0) {
      s.type = ShapeType::kCapsule;
      s.length = d[b];
      s.placement.translation = Vector3(0, 0, d[b] / 2);
    } else {
      s.type = ShapeType::kSphere;
    }
    g.body_shapes[b].push_back(static_cast<int>(g.shapes.size()));
    g.shapes.push_back(s);
  }
  return g;
}

/// One capsule per body of an arbitrary chain: from the body origin to the next joint's origin
/// (the last body gets a short capsule along its x axis).
inline GeometryModel chain_capsules(const Model& model, double radius = 0.05) {
  GeometryModel g;
  g.body_shapes.resize(static_cast<std::size_t>(model.num_bodies()));
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Vector3 end =
        b + 1 < model.num_bodies() ? model.joints[b + 1].placement.translation : Vector3(0.1, 0, 0);
    CollisionShape s;
    s.type = ShapeType::kCapsule;
    s.body = b;
    s.link = model.bodies[b].name;
    s.radius = radius;
    s.length = std::max(end.norm(), 1e-3);
    // Capsule axis = shape z: rotate z onto `end`.
    const Vector3 z = end.norm() > 1e-9 ? Vector3(end.normalized()) : Vector3::UnitZ();
    s.placement.rotation =
        Eigen::Quaterniond::FromTwoVectors(Vector3::UnitZ(), z).toRotationMatrix();
    s.placement.translation = 0.5 * end;
    g.body_shapes[b].push_back(static_cast<int>(g.shapes.size()));
    g.shapes.push_back(s);
  }
  return g;
}

/// A random point on the surface of shape `s` (sphere, or the cylindrical part of a capsule),
/// in the body frame, with its outward normal (body frame).
inline std::pair<Vector3, Vector3> random_surface_point(const CollisionShape& s, SeededRng& rng) {
  Vector3 normal = rng.uniform_vector3(-1, 1).normalized();
  Vector3 c = Vector3::Zero();
  if (s.type == ShapeType::kCapsule) {
    c.z() = rng.uniform(-0.45, 0.45) * s.length;
    normal.z() = 0;
    normal.normalize();
  }
  const Vector3 p_S = c + s.radius * normal;
  return {s.placement.act(p_S), s.placement.rotation * normal};
}

/// A contact at a random point of shape `s` on a link at pose X_WL: the point (link frame and
/// W), a force of 5-50 N pushing into the surface (its inward normal share at least 0.3: never
/// grazing) and, `with_moment`, a pure moment in [-2, 2]^3 N m (else zero); all in W.
struct SurfacePush {
  Vector3 p_L, p_W, force_W, moment_W;
};
inline SurfacePush random_surface_push(const CollisionShape& s, const Pose& X_WL, SeededRng& rng,
                                       bool with_moment) {
  const auto [p_L, normal_L] = random_surface_point(s, rng);
  const Vector3 normal_W = X_WL.rotation * normal_L;
  Vector3 dir = rng.uniform_vector3(-1, 1).normalized();
  if (dir.dot(normal_W) > 0) dir = -dir;
  if (dir.dot(normal_W) > -0.3) dir = (dir - normal_W).normalized();
  SurfacePush push{p_L, X_WL.act(p_L), Vector3::Zero(), Vector3::Zero()};
  push.force_W = rng.uniform(5, 50) * dir;
  if (with_moment) push.moment_W = rng.uniform_vector3(-2, 2);
  return push;
}

/// The model as a URDF string (one <link> per body, one revolute/prismatic <joint> per joint,
/// extra frames omitted), for kdl_parser.
inline std::string model_to_urdf(const Model& model) {
  std::ostringstream o;
  o.precision(17);
  auto vec = [&](const Vector3& v) {
    std::ostringstream s;
    s.precision(17);
    s << v.x() << ' ' << v.y() << ' ' << v.z();
    return s.str();
  };
  o << "<robot name=\"" << model.name << "\">\n";
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Inertia& in = model.bodies[b].inertia;
    const Matrix3& I = in.inertia_com;
    o << "<link name=\"" << model.bodies[b].name << "\"><inertial><origin xyz=\"" << vec(in.com)
      << "\" rpy=\"0 0 0\"/><mass value=\"" << in.mass << "\"/><inertia ixx=\"" << I(0, 0)
      << "\" ixy=\"" << I(0, 1) << "\" ixz=\"" << I(0, 2) << "\" iyy=\"" << I(1, 1) << "\" iyz=\""
      << I(1, 2) << "\" izz=\"" << I(2, 2) << "\"/></inertial></link>\n";
  }
  for (int i = 1; i < model.num_bodies(); ++i) {
    const Joint& j = model.joints[i];
    o << "<joint name=\"" << j.name << "\" type=\""
      << (j.type == JointType::kRevolute ? "continuous" : "prismatic") << "\"><parent link=\""
      << model.bodies[model.parents[i]].name << "\"/><child link=\"" << model.bodies[i].name
      << "\"/><origin xyz=\"" << vec(j.placement.translation) << "\" rpy=\""
      << vec(rpy_from_rotation(j.placement.rotation)) << "\"/><axis xyz=\"" << vec(j.axis)
      << "\"/>";
    if (j.type == JointType::kPrismatic)
      o << "<limit lower=\"-10\" upper=\"10\" effort=\"1000\" velocity=\"10\"/>";
    o << "</joint>\n";
  }
  o << "</robot>\n";
  return o.str();
}

/// Each body's mass, CoM coordinates and inertia entries scaled by independent factors
/// uniform in [1 − e, 1 + e] (paper Sec. IV; zero entries stay zero, symmetry kept).
inline Model perturbed_model(const Model& nominal, double e, unsigned seed) {
  SeededRng rng(seed);
  Model m = nominal;
  for (Body& b : m.bodies) {
    b.inertia.mass *= 1 + rng.uniform(-e, e);
    for (int k = 0; k < 3; ++k) b.inertia.com[k] *= 1 + rng.uniform(-e, e);
    Matrix3& I = b.inertia.inertia_com;
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) {
        I(r, c) *= 1 + rng.uniform(-e, e);
        I(c, r) = I(r, c);
      }
    }
  }
  return m;
}

/// The true robot: RK4 of B q̈ + c + τ_f = τ + τ_ext(q, q̇) with τ held over a step.
class SimulatedArm {
 public:
  /// Adds the external joint torques of the current state into tau_ext (already zeroed).
  using ExternalTorque = std::function<void(const Model&, Data&, double t, const VectorX& q,
                                            const VectorX& dq, VectorX& tau_ext)>;

  explicit SimulatedArm(Model model) : model_(std::move(model)), data_(model_) {
    q = VectorX::Zero(model_.nq());
    dq = VectorX::Zero(model_.nq());
    friction_viscous = VectorX::Zero(model_.nq());
  }

  VectorX acceleration(double t, const VectorX& qs, const VectorX& dqs, const VectorX& tau) {
    VectorX tau_ext = VectorX::Zero(model_.nq());
    if (external) external(model_, data_, t, qs, dqs, tau_ext);
    const VectorX total = tau + tau_ext - friction_viscous.cwiseProduct(dqs);
    if (!forward_dynamics(model_, data_, qs, dqs, total)) throw std::runtime_error("B not PD");
    return data_.ddq;
  }

  void step(const VectorX& tau, double h) {
    const VectorX a1 = acceleration(t, q, dq, tau);
    const VectorX q2 = q + 0.5 * h * dq, v2 = dq + 0.5 * h * a1;
    const VectorX a2 = acceleration(t + 0.5 * h, q2, v2, tau);
    const VectorX q3 = q + 0.5 * h * v2, v3 = dq + 0.5 * h * a2;
    const VectorX a3 = acceleration(t + 0.5 * h, q3, v3, tau);
    const VectorX q4 = q + h * v3, v4 = dq + h * a3;
    const VectorX a4 = acceleration(t + h, q4, v4, tau);
    q += h / 6 * (dq + 2 * v2 + 2 * v3 + v4);
    dq += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    t += h;
  }

  /// External joint torques and the acceleration at the current state under τ.
  VectorX external_torque_now() {
    VectorX tau_ext = VectorX::Zero(model_.nq());
    if (external) external(model_, data_, t, q, dq, tau_ext);
    return tau_ext;
  }

  const Model& model() const { return model_; }
  Data& data() { return data_; }

  double t = 0.0;
  VectorX q, dq;
  VectorX friction_viscous;
  ExternalTorque external;

 private:
  Model model_;
  Data data_;
};

/// τ_ext = Jᵀ W of a force F_W applied at a point fixed in body `body` (p_B in body frame) plus a
/// pure moment, from our RNEA with and without the wrench.
inline void add_body_force_torque(const Model& model, Data& data, const VectorX& q,
                                  const VectorX& dq, int body, const Vector3& p_B,
                                  const Vector3& F_W, const Vector3& M_W, VectorX& tau_ext) {
  const VectorX zero = VectorX::Zero(model.nq());
  forward_kinematics(model, data, q);
  ExternalWrench w;
  w.body = body;
  w.point_W = data.X_WB[body].act(p_B);
  w.force_W = F_W;
  w.moment_W = M_W;
  const VectorX free = rnea(model, data, q, dq, zero);
  const VectorX with = rnea(model, data, q, dq, zero, std::span<const ExternalWrench>(&w, 1));
  tau_ext += free - with;
}

/// A smooth joint trajectory and a computed-torque + PD controller on a (perturbed) model.
struct SineTracker {
  VectorX q0, amplitude, frequency;  // [rad], [rad], [Hz]
  double kp = 100.0, kd = 20.0;

  explicit SineTracker(int n) {
    q0 = VectorX::Zero(n);
    amplitude = VectorX::Constant(n, 0.4);
    frequency = VectorX::Zero(n);
    for (int i = 0; i < n; ++i) frequency[i] = 0.15 + 0.05 * i;
  }
  void desired(double t, VectorX& qd, VectorX& dqd, VectorX& ddqd) const {
    const int n = static_cast<int>(q0.size());
    qd.resize(n);
    dqd.resize(n);
    ddqd.resize(n);
    for (int i = 0; i < n; ++i) {
      const double w = 2 * std::numbers::pi * frequency[i];
      qd[i] = q0[i] + amplitude[i] * std::sin(w * t);
      dqd[i] = amplitude[i] * w * std::cos(w * t);
      ddqd[i] = -amplitude[i] * w * w * std::sin(w * t);
    }
  }
  VectorX torque(const Model& ctrl_model, Data& ctrl_data, double t, const VectorX& q,
                 const VectorX& dq) const {
    VectorX qd, dqd, ddqd;
    desired(t, qd, dqd, ddqd);
    const VectorX a = ddqd + kp * (qd - q) + kd * (dqd - dq);
    return rnea(ctrl_model, ctrl_data, q, dq, a);
  }
};

}  // namespace extwrench::test
