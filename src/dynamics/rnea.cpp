#include "extwrench/dynamics/rnea.hpp"

#include "argument_checks.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "spatial.hpp"

namespace extwrench {

namespace {

// External wrenches and the backward pass (9)-(12), down to i = 0: f_0 is what the ground
// applies to link 0. data.f holds each body's own I_i a_i + v_i x* I_i v_i on entry.
const VectorX& backward_pass(const Model& model, Data& data,
                             std::span<const ExternalWrench> external) {
  const int nb = model.num_bodies();
  // External wrenches: force at p plus pure moment, moved to the world origin (Remark 4).
  for (const ExternalWrench& w : external) {
    data.f[w.body].head<3>() -= w.force_W;
    data.f[w.body].tail<3>() -= w.moment_W + w.point_W.cross(w.force_W);
  }
  // The subtree wrench of the child just finished is carried in registers along a chain; at a
  // branching of a tree it is added into the parent's entry of data.f instead.
  Vector3 F_child = Vector3::Zero();
  Vector3 N_child = Vector3::Zero();
  for (int i = nb - 1; i > 0; --i) {
    const int p = model.parents[i];
    const bool chain_child = i + 1 < nb && model.parents[i + 1] == i;
    Vector3 F = data.f[i].head<3>();
    Vector3 N = data.f[i].tail<3>();
    if (chain_child) {
      F += F_child;
      N += N_child;
    }
    data.f[i].head<3>() = F;  // f_i: the wrench joint i transmits (the subtree's)
    data.f[i].tail<3>() = N;
    data.tau[i - 1] = data.S[i].head<3>().dot(F) + data.S[i].tail<3>().dot(N);
    if (p == i - 1) {
      F_child = F;
      N_child = N;
    } else {
      data.f[p].head<3>() += F;
      data.f[p].tail<3>() += N;
      F_child.setZero();
      N_child.setZero();
    }
  }
  if (nb > 1 && model.parents[1] == 0) {
    data.f[0].head<3>() += F_child;
    data.f[0].tail<3>() += N_child;
  }
  data.root_wrench_W = data.f[0];
  return data.tau;
}

// rnea's 3-vectors as three doubles: Eigen's Vector3 arithmetic under SSE2 mixes 2-double
// packets with scalars, and rebuilt packets from scalars through the stack, each one a
// store-forwarding stall (they were most of rnea's time in `perf annotate`).
struct Vec {
  double x, y, z;
};
[[gnu::always_inline]] inline Vec operator+(const Vec& a, const Vec& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
[[gnu::always_inline]] inline Vec operator*(double k, const Vec& a) {
  return {k * a.x, k * a.y, k * a.z};
}
[[gnu::always_inline]] inline Vec cross(const Vec& a, const Vec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// M x for a column-major 3x3.
[[gnu::always_inline]] inline Vec times(const Matrix3& M, const Vec& x) {
  const double* m = M.data();
  return {m[0] * x.x + m[3] * x.y + m[6] * x.z, m[1] * x.x + m[4] * x.y + m[7] * x.z,
          m[2] * x.x + m[5] * x.y + m[8] * x.z};
}
/// Rz(c, s) x and Rz(c, s)^T x: the joint's turn of the first two coordinates.
[[gnu::always_inline]] inline Vec rotate_z(double c, double s, const Vec& x) {
  return {c * x.x - s * x.y, s * x.x + c * x.y, x.z};
}
[[gnu::always_inline]] inline Vec rotate_z_inverse(double c, double s, const Vec& x) {
  return {c * x.x + s * x.y, c * x.y - s * x.x, x.z};
}
/// Three consecutive coefficients of an Eigen vector (Vector3 or Vector6) from `offset`.
template <typename V>
[[gnu::always_inline]] inline Vec load(const V& v, int offset = 0) {
  return {v[offset], v[offset + 1], v[offset + 2]};
}
template <typename V>
[[gnu::always_inline]] inline void store(const Vec& x, V& v, int offset) {
  v[offset] = x.x;
  v[offset + 1] = x.y;
  v[offset + 2] = x.z;
}
/// Joint i's origin in its parent's aligned frame: t'_i + slide'_i q_i.
[[gnu::always_inline]] inline Vec joint_origin(const Data::AlignedBody& b, double qi) {
  return load(b.translation) + qi * load(b.slide);
}

}  // namespace

const VectorX& rnea(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                    const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& ddq,
                    std::span<const ExternalWrench> external) {
  detail::check_data("rnea", model, data);
  detail::check_joint_vector("rnea", "q", q.size(), model);
  detail::check_joint_vector("rnea", "dq", dq.size(), model);
  detail::check_joint_vector("rnea", "ddq", ddq.size(), model);
  for (const ExternalWrench& w : external)
    detail::check_body("rnea", "external wrench body", w.body, model);
  // Featherstone's form in each body's joint-aligned frame J_i (Data::aligned): the motion
  // comes into J_i through E'_i(q)^T = Rz(q)^T P'^T, Newton-Euler uses J_i's constant mass
  // properties about its origin, and the wrench goes back through E'_i. The joint is e_z there,
  // so S q_dot, S q_ddot, v x S q_dot and S^T f are a few scalars; no world pose is formed
  // (docs/algorithms.md, "Inverse dynamics").
  const int nb = model.num_bodies();
  // The external wrenches need world poses; forward_poses leaves in data.sin_q, data.cos_q the
  // very sines and cosines this pass needs (detail::joint_sin_cos, the same polynomial).
  if (!external.empty()) {
    forward_poses(model, data, q);
  } else {
    detail::sin_cos_poly_n(q.data(), data.sin_q.data(), data.cos_q.data(), nb - 1);
  }
  // Prismatic joints turn by 0: (c, s) = (1, 0) keeps one path for both types.
  for (int j = 0; j < nb - 1; ++j) {
    const double r = data.aligned[static_cast<std::size_t>(j + 1)].revolute;
    data.sin_q[j] *= r;
    data.cos_q[j] = r * data.cos_q[j] + (1.0 - r);
  }
  // Gravity trick: the base accelerates with -g (docs/method.md). J_0 is the world frame.
  {
    const Data::AlignedBody& b = data.aligned[0];
    const Vec a0 = -1.0 * load(model.gravity);
    const Vec zero{0.0, 0.0, 0.0};
    store(zero, data.w_J[0], 0);
    store(a0, data.a_J[0], 0);
    store(zero, data.a_J[0], 3);
    store(b.mass * a0, data.f_J[0], 0);
    store(cross(load(b.first_moment), a0), data.f_J[0], 3);
  }
  for (int i = 1; i < nb; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const auto up = static_cast<std::size_t>(model.parents[ui]);
    // The parent's angular velocity w, angular acceleration w_dot and the classical linear
    // acceleration a of its origin (no linear velocity is needed: Newton-Euler about an origin
    // uses its acceleration only).
    Vec w = load(data.w_J[up], 0);
    Vec a = load(data.a_J[up], 0);
    Vec w_dot = load(data.a_J[up], 3);
    const Data::AlignedBody& b = data.aligned[ui];
    const double c = data.cos_q[i - 1];
    const double s = data.sin_q[i - 1];
    const double qd = dq[i - 1];
    const double qdd = ddq[i - 1];
    const double r = b.revolute;
    const Vec t = joint_origin(b, q[i - 1]);
    // The acceleration of this joint's origin as a point of the parent, then all into J_i.
    a = rotate_z_inverse(c, s, times(b.rotation_T, a + cross(w_dot, t) + cross(w, cross(w, t))));
    w = rotate_z_inverse(c, s, times(b.rotation_T, w));
    w_dot = rotate_z_inverse(c, s, times(b.rotation_T, w_dot));
    // The joint, e_z in J_i: revolute w += e_z q_dot, w_dot += e_z q_ddot + w x e_z q_dot;
    // prismatic: the origin slides, a += e_z q_ddot + 2 w x e_z q_dot (Coriolis).
    const double coriolis = 2.0 * (1.0 - r) * qd;  // 0 for a revolute joint
    a.x += coriolis * w.y;
    a.y -= coriolis * w.x;
    a.z += (1.0 - r) * qdd;
    const double turn = r * qd;  // 0 for a prismatic joint
    w.z += turn;
    w_dot.x += turn * w.y;
    w_dot.y -= turn * w.x;
    w_dot.z += r * qdd;
    // Eqs. (7)-(8) about J_i's origin, with h = m c and I_O constant in J_i.
    const Vec h = load(b.first_moment);
    const Vec F = b.mass * a + cross(w_dot, h) + cross(w, cross(w, h));
    const Vec N = times(b.inertia_O, w_dot) + cross(w, times(b.inertia_O, w)) + cross(h, a);
    store(w, data.w_J[ui], 0);
    store(a, data.a_J[ui], 0);
    store(w_dot, data.a_J[ui], 3);
    store(F, data.f_J[ui], 0);
    store(N, data.f_J[ui], 3);
  }
  if (!external.empty()) {
    // World wrenches into J_i: the body's world pose (forward_poses, run first) times A_i.
    for (const ExternalWrench& e : external) {
      const auto ub = static_cast<std::size_t>(e.body);
      const Pose& X = data.X_WB[ub];
      const Matrix3 R = X.rotation * data.aligned[ub].alignment;
      const Vector3 moment = e.moment_W + (e.point_W - X.translation).cross(e.force_W);
      data.f_J[ub].head<3>() -= R.transpose() * e.force_W;
      data.f_J[ub].tail<3>() -= R.transpose() * moment;
    }
  }
  // Backward: the subtree's wrench, carried in registers along a chain.
  Vec F_child{0.0, 0.0, 0.0};
  Vec N_child{0.0, 0.0, 0.0};
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<std::size_t>(i);
    const int p = model.parents[ui];
    const bool chain_child = i + 1 < nb && model.parents[ui + 1] == i;
    Vec F = load(data.f_J[ui], 0);
    Vec N = load(data.f_J[ui], 3);
    if (chain_child) {
      F = F + F_child;
      N = N + N_child;
    }
    const Data::AlignedBody& b = data.aligned[ui];
    const double r = b.revolute;
    data.tau[i - 1] = r * N.z + (1.0 - r) * F.z;
    // Into J_p, about its origin.
    const double c = data.cos_q[i - 1];
    const double s = data.sin_q[i - 1];
    const Vec t = joint_origin(b, q[i - 1]);
    const Vec F_p = times(b.rotation, rotate_z(c, s, F));
    const Vec N_p = times(b.rotation, rotate_z(c, s, N)) + cross(t, F_p);
    if (p == i - 1) {
      F_child = F_p;
      N_child = N_p;
    } else {
      Vector6& f_p = data.f_J[static_cast<std::size_t>(p)];
      store(load(f_p, 0) + F_p, f_p, 0);
      store(load(f_p, 3) + N_p, f_p, 3);
      F_child = {0.0, 0.0, 0.0};
      N_child = {0.0, 0.0, 0.0};
    }
  }
  Vector6 f0 = data.f_J[0];
  if (nb > 1 && model.parents[1] == 0) {
    store(load(f0, 0) + F_child, f0, 0);
    store(load(f0, 3) + N_child, f0, 3);
  }
  data.root_wrench_W = f0;                           // J_0 is the world frame
  detail::add_armature_times(model, ddq, data.tau);  // the rotors: not in the base wrench
  return data.tau;
}

const VectorX& rnea_no_kinematics(const Model& model, Data& data,
                                  const Eigen::Ref<const VectorX>& dq,
                                  const Eigen::Ref<const VectorX>& ddq,
                                  std::span<const ExternalWrench> external, bool with_gravity) {
  detail::check_data("rnea_no_kinematics", model, data);
  detail::check_joint_vector("rnea_no_kinematics", "dq", dq.size(), model);
  detail::check_joint_vector("rnea_no_kinematics", "ddq", ddq.size(), model);
  for (const ExternalWrench& w : external)
    detail::check_body("rnea_no_kinematics", "external wrench body", w.body, model);
  const int nb = model.num_bodies();
  // Forward pass. Gravity trick: the base accelerates with -g (docs/method.md).
  data.v[0].setZero();
  data.a[0].setZero();
  if (with_gravity) data.a[0].head<3>() = -model.gravity;
  for (int i = 0; i < nb; ++i) {
    if (i > 0) {
      const int p = model.parents[i];
      const Vector6& s = data.S[i];
      const Vector6 vj = s * dq[i - 1];
      data.v[i] = data.v[p] + vj;
      // a_i = a_p + S q_ddot + S_dot q_dot, with S_dot = v_p x S (S is fixed in the parent).
      data.a[i] = data.a[p] + s * ddq[i - 1] + detail::cross_motion(data.v[p], vj);
    }
    // (7)-(8) in spatial form: f_i = I_i a_i + v_i x* I_i v_i
    const Vector6 hi =
        detail::inertia_times(data.mass[i], data.first_moment_W[i], data.inertia_O_W[i], data.v[i]);
    data.f[i] = detail::inertia_times(data.mass[i], data.first_moment_W[i], data.inertia_O_W[i],
                                      data.a[i]) +
                detail::cross_force(data.v[i], hi);
  }
  backward_pass(model, data, external);
  detail::add_armature_times(model, ddq, data.tau);
  return data.tau;
}

Vector6 sensor_reading_world(const Data& data, const Vector3& p_WS) {
  // f_m = -f_0, n_m = -(n_0 about O_s) = -(n_O - p_s x f_0)
  const Vector6& f0 = data.root_wrench_W;
  Vector6 out;
  out.head<3>() = -f0.head<3>();
  out.tail<3>() = -(f0.tail<3>() - p_WS.cross(f0.head<3>()));
  return out;
}

Vector6 sensor_reading(const Data& data, const Pose& X_WS) {
  // As sensor_reading_world, then rotated into the sensor frame: [R^T f_m; R^T n_m].
  const Vector3 F0 = data.root_wrench_W.head<3>();
  const Vector3 N0 = data.root_wrench_W.tail<3>();
  const Vector3 n_m = X_WS.translation.cross(F0) - N0;
  Vector6 out;
  out.head<3>().noalias() = -(X_WS.rotation.transpose() * F0);
  out.tail<3>().noalias() = X_WS.rotation.transpose() * n_m;
  return out;
}

const VectorX& bias_torques(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                            const Eigen::Ref<const VectorX>& dq) {
  // rnea at q_ddot = 0: its fused pass needs no world inertia R I_c R^T (forward_kinematics
  // followed by rnea_no_kinematics formed them all).
  data.tmp_n.setZero();
  return rnea(model, data, q, dq, data.tmp_n);
}

const VectorX& gravity_torques(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  detail::check_data("gravity_torques", model, data);
  detail::check_joint_vector("gravity_torques", "q", q.size(), model);
  // g_i = -S_i^T [m^c_i g; h^c_i x g] (the subtree's weight as a wrench), evaluated in body i's
  // own frame, where S_i is the constant data.S_B[i]: no world pose, no inertia tensor, no
  // velocity. Forward: the gravity vector in each body's axes, g_i = E_i(q)^T g_p. Backward: the
  // subtree's mass and first moment about body i's origin, h^c_p += m^c_i t_i + E_i h^c_i with
  // t_i = placement_i + slide_i q_i. Both products go through detail::rotation_times (E^T from
  // Data's transposed constants), so no 3x3 is formed. Along a chain the carried vectors stay in
  // registers.
  const int nb = model.num_bodies();
  // Not detail::joint_sin_cos: glibc's sincos was a third of this pass (sin_cos_poly).
  detail::sin_cos_poly_n(q.data(), data.sin_q.data(), data.cos_q.data(), nb - 1);
  Vector3 g = model.gravity;  // body 0 is the world frame
  data.gravity_B[0] = g;
  {
    const Inertia& inertia = model.bodies[0].inertia;
    data.composite_mass[0] = inertia.mass;
    data.composite_first_moment_B[0] = inertia.mass * inertia.com;
  }
  for (int i = 1; i < nb; ++i) {
    if (model.parents[i] != i - 1) g = data.gravity_B[model.parents[i]];
    const double c = data.cos_q[i - 1];
    const double s = data.sin_q[i - 1];
    const Vector3 g_i = detail::rotation_times(data.rotation_const_T[i], data.rotation_cos_T[i],
                                               data.rotation_sin_T[i], c, s, g);
    g = g_i;
    data.gravity_B[i] = g_i;
    // The torque's gravity factors, off the backward pass's critical path:
    // torque_i = -(m^c_i s_lin . g_i + h^c_i . (g_i x s_ang)).
    const Vector6& S = data.S_B[i];
    data.gravity_lin_B[i] = S.head<3>().dot(g_i);
    data.gravity_moment_B[i] = g_i.cross(S.tail<3>());
    const Inertia& inertia = model.bodies[i].inertia;
    data.composite_mass[i] = inertia.mass;
    data.composite_first_moment_B[i] = inertia.mass * inertia.com;
  }
  double m_child = 0.0;  // the chain child's subtree, in this body's axes about its origin
  Vector3 h_child = Vector3::Zero();
  for (int i = nb - 1; i > 0; --i) {
    const int p = model.parents[i];
    const bool chain_child = i + 1 < nb && model.parents[i + 1] == i;
    double m = data.composite_mass[i];
    Vector3 h = data.composite_first_moment_B[i];
    if (chain_child) {
      m += m_child;
      h += h_child;
    }
    data.composite_mass[i] = m;
    data.composite_first_moment_B[i] = h;
    data.gravity_torque[i - 1] = -(m * data.gravity_lin_B[i] + h.dot(data.gravity_moment_B[i]));
    // Into the parent's frame: X_pi = (E_i, t_i).
    const double c = data.cos_q[i - 1];
    const double s = data.sin_q[i - 1];
    const Vector3 t = model.joints[i].placement.translation + data.slide_P[i] * q[i - 1];
    const Vector3 h_p = m * t + detail::rotation_times(data.rotation_const[i], data.rotation_cos[i],
                                                       data.rotation_sin[i], c, s, h);
    if (p == i - 1) {
      m_child = m;
      h_child = h_p;
    } else {
      data.composite_mass[p] += m;
      data.composite_first_moment_B[p] += h_p;
      m_child = 0.0;
      h_child.setZero();
    }
  }
  if (nb > 1 && model.parents[1] == 0) {
    data.composite_mass[0] += m_child;
    data.composite_first_moment_B[0] += h_child;
  }
  return data.gravity_torque;
}

const MatrixX& coriolis_matrix(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq) {
  detail::check_data("coriolis_matrix", model, data);
  detail::check_joint_vector("coriolis_matrix", "q", q.size(), model);
  detail::check_joint_vector("coriolis_matrix", "dq", dq.size(), model);
  forward_kinematics(model, data, q);
  const int nb = model.num_bodies();
  data.v[0].setZero();
  for (int i = 1; i < nb; ++i) {
    data.v[i] = data.v[model.parents[i]] + data.S[i] * dq[i - 1];
    data.Sdot[i] = detail::cross_motion(data.v[i], data.S[i]);
  }
  for (int i = 0; i < nb; ++i) {
    data.Ic[i] = detail::inertia_matrix(data.mass[i], data.first_moment_W[i], data.inertia_O_W[i]);
    data.Bc[i] = detail::cross_force_matrix(data.v[i]) * data.Ic[i];
  }
  data.C.setZero();
  // C = sum_k J_k^T (I_k J_dot_k + (v_k x*) I_k J_k), so that B_dot = C + C^T. With composites
  // Ic_i, Bc_i over the subtree of i, for every ancestor j of i (j = i included):
  //   C_ij = S_i^T (Ic_i S_dot_j + Bc_i S_j),  C_ji = S_j^T (Ic_i S_dot_i + Bc_i S_i).
  for (int i = nb - 1; i > 0; --i) {
    const Vector6 Fi = data.Ic[i] * data.Sdot[i] + data.Bc[i] * data.S[i];
    const Vector6 Si_Ic = data.Ic[i].transpose() * data.S[i];
    const Vector6 Si_Bc = data.Bc[i].transpose() * data.S[i];
    for (int j = i; j > 0; j = model.parents[j]) {
      data.C(i - 1, j - 1) = Si_Ic.dot(data.Sdot[j]) + Si_Bc.dot(data.S[j]);
      data.C(j - 1, i - 1) = data.S[j].dot(Fi);
    }
    const int p = model.parents[i];
    data.Ic[p] += data.Ic[i];
    data.Bc[p] += data.Bc[i];
  }
  return data.C;
}
}  // namespace extwrench
