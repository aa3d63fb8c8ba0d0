#include "extwrench/dynamics/rnea.hpp"

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

}  // namespace

const VectorX& rnea(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                    const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& ddq,
                    std::span<const ExternalWrench> external) {
  // One pass: poses and S as in forward_kinematics, then Newton-Euler of each body about its
  // CoM with the constant body-axes inertia I_c, so that no world inertia R I_c R^T is formed
  // (that rotation was most of forward_kinematics; rnea_no_kinematics reuses it instead).
  const int nb = model.num_bodies();
  data.X_WB[0] = Pose{};
  data.S[0].setZero();
  data.v[0].setZero();
  data.a[0].setZero();
  // Gravity trick: the base accelerates with -g (docs/method.md).
  data.a[0].head<3>() = -model.gravity;
  {
    // Link 0 is at rest in the world frame: f_0 = [m (-g); c x m (-g)].
    const Inertia& inertia = model.bodies[0].inertia;
    const Vector3 F = -inertia.mass * model.gravity;
    data.f[0] << F, inertia.com.cross(F);
  }
  // The parent's motion [v_O; w], [a_O; w_dot] is carried in registers along a chain (body
  // i - 1), reloaded from data only at a branching of a tree.
  Vector3 v_O = Vector3::Zero();
  Vector3 w = Vector3::Zero();
  Vector3 a_O = -model.gravity;
  Vector3 w_dot = Vector3::Zero();
  Pose X_parent;  // likewise the parent's pose
  detail::joint_sin_cos(model, data, q);
  for (int i = 1; i < nb; ++i) {
    const int p = model.parents[i];
    if (p != i - 1) {
      X_parent = data.X_WB[p];
      v_O = data.v[p].head<3>();
      w = data.v[p].tail<3>();
      a_O = data.a[p].head<3>();
      w_dot = data.a[p].tail<3>();
    }
    Matrix3 R;
    Vector3 O;
    Vector3 s_lin;
    Vector3 s_ang;
    detail::joint_kinematics(model, data, i, X_parent, q[i - 1], R, O, s_lin, s_ang);
    detail::propagate_motion<true>(s_lin, s_ang, dq[i - 1], ddq[i - 1], v_O, w, a_O, w_dot);
    const Inertia& inertia = model.bodies[i].inertia;
    const Vector3 c = R * inertia.com + O;
    const Vector3 v_c = v_O + w.cross(c);
    const Vector3 w_B = R.transpose() * w;
    Vector3 F;
    Vector3 N;
    detail::newton_euler_about_com(inertia, R, c, v_c, w, a_O, w_dot, w_B,
                                   inertia.inertia_com * w_B, F, N);
    data.X_WB[i].rotation = R;
    data.X_WB[i].translation = O;
    data.S[i].head<3>() = s_lin;
    data.S[i].tail<3>() = s_ang;
    data.v[i].head<3>() = v_O;
    data.v[i].tail<3>() = w;
    data.a[i].head<3>() = a_O;
    data.a[i].tail<3>() = w_dot;
    data.f[i].head<3>() = F;
    data.f[i].tail<3>() = N;
    X_parent.rotation = R;
    X_parent.translation = O;
  }
  backward_pass(model, data, external);
  detail::add_armature_times(model, ddq, data.tau);  // the rotors: not in the base wrench
  return data.tau;
}

const VectorX& rnea_no_kinematics(const Model& model, Data& data,
                                  const Eigen::Ref<const VectorX>& dq,
                                  const Eigen::Ref<const VectorX>& ddq,
                                  std::span<const ExternalWrench> external, bool with_gravity) {
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
  // g_i = -S_i^T [m^c_i g; h^c_i x g] (the subtree's weight as a wrench), evaluated in body i's
  // own frame, where S_i is the constant data.S_B[i]: no world pose, no inertia tensor, no
  // velocity. Forward: the gravity vector in each body's axes, g_i = E_i(q)^T g_p. Backward: the
  // subtree's mass and first moment about body i's origin, h^c_p += m^c_i t_i + E_i h^c_i with
  // t_i = placement_i + slide_i q_i. Both products go through detail::rotation_times (E^T from
  // Data's transposed constants), so no 3x3 is formed. Along a chain the carried vectors stay in
  // registers.
  const int nb = model.num_bodies();
  // Not detail::joint_sin_cos: glibc's sincos was a third of this pass (sin_cos_poly).
  for (int j = 0; j < nb - 1; ++j) detail::sin_cos_poly(q[j], data.sin_q[j], data.cos_q[j]);
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
