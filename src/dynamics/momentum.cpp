#include "extwrench/dynamics/momentum.hpp"

#include "argument_checks.hpp"
#include "spatial.hpp"

namespace extwrench {

namespace {

/// One pass over the bodies for momentum_terms (and, with `full`, momentum_and_bias_terms): the
/// poses, each body's momentum about its CoM with the constant body-axes inertia I_c (no world
/// inertia R I_c R^T is formed unless `full` asks for the world mass properties), and with
/// `full` the bias wrench f_i = I_i a_i + v_i x* h_i at q_ddot = 0 (gravity trick). Along a
/// chain the parent's pose and motion stay in registers.
// Not split (~170 lines): one fused forward + backward recursion whose carried registers are the
// point.
template <bool full>
void momentum_pass(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                   const Eigen::Ref<const VectorX>& dq) {
  const int nb = model.num_bodies();
  const Vector3& g = model.gravity;
  data.X_WB[0] = Pose{};
  data.S[0].setZero();
  data.v[0].setZero();
  data.f[0].setZero();  // link 0 is at rest: no momentum
  data.h[0].setZero();
  {
    const Inertia& inertia = model.bodies[0].inertia;
    data.composite_mass[0] = inertia.mass;
    data.composite_first_moment[0] = inertia.mass * inertia.com;
    if constexpr (full) {
      data.a[0].setZero();
      data.a[0].head<3>() = -g;
      // Link 0's weight, carried by the ground: f_0 = [m (-g); c x m (-g)].
      const Vector3 F = -inertia.mass * g;
      data.bias_f[0] << F, inertia.com.cross(F);
    }
  }
  if constexpr (full) detail::world_mass_properties_of(model, data, 0);
  Pose X_parent;
  Vector3 v_O = Vector3::Zero();
  Vector3 w = Vector3::Zero();
  Vector3 a_O = -g;
  Vector3 w_dot = Vector3::Zero();
  detail::joint_sin_cos(model, data, q);
  for (int i = 1; i < nb; ++i) {
    const int p = model.parents[i];
    if (p != i - 1) {
      X_parent = data.X_WB[p];
      v_O = data.v[p].head<3>();
      w = data.v[p].tail<3>();
      if constexpr (full) {
        a_O = data.a[p].head<3>();
        w_dot = data.a[p].tail<3>();
      }
    }
    Matrix3 R;
    Vector3 O;
    Vector3 s_lin;
    Vector3 s_ang;
    detail::joint_kinematics(model, data, i, X_parent, q[i - 1], R, O, s_lin, s_ang);
    detail::propagate_motion<full>(s_lin, s_ang, dq[i - 1], 0.0, v_O, w, a_O, w_dot);
    const Inertia& inertia = model.bodies[i].inertia;
    const Vector3 c = R * inertia.com + O;
    // h_i about the world origin: [m v_c; I_c,W w + c x m v_c], v_c the velocity of the CoM.
    const Vector3 v_c = v_O + w.cross(c);
    const Vector3 L = inertia.mass * v_c;
    const Vector3 w_B = R.transpose() * w;
    const Vector3 Iw_B = inertia.inertia_com * w_B;
    const Vector3 K = R * Iw_B + c.cross(L);  // I_c,W w + c x L
    data.X_WB[i].rotation = R;
    data.X_WB[i].translation = O;
    data.S[i].head<3>() = s_lin;
    data.S[i].tail<3>() = s_ang;
    data.v[i].head<3>() = v_O;
    data.v[i].tail<3>() = w;
    data.h[i].head<3>() = L;
    data.h[i].tail<3>() = K;
    data.f[i].head<3>() = L;  // f accumulates H_i = sum of h_k over sub(i) below
    data.f[i].tail<3>() = K;
    data.composite_mass[i] = inertia.mass;
    data.composite_first_moment[i] = inertia.mass * c;
    if constexpr (full) {
      data.a[i].head<3>() = a_O;
      data.a[i].tail<3>() = w_dot;
      Vector3 F;  // the bias wrench at q_ddot = 0
      Vector3 N;
      detail::newton_euler_about_com(inertia, R, c, v_c, w, a_O, w_dot, w_B, Iw_B, F, N);
      data.bias_f[i].head<3>() = F;
      data.bias_f[i].tail<3>() = N;
      detail::world_mass_properties_of(model, data, i);
    }
    X_parent.rotation = R;
    X_parent.translation = O;
  }
  // Subtree sums, in 3-vectors: along a chain the child's are carried in registers (as in
  // rnea's backward pass), at a branching added into the parent's entries. (6-vectors read
  // back whole after piecewise writes would stall store forwarding.)
  Vector3 L_child = Vector3::Zero();  // H = [L; K]: subtree momentum about the world origin
  Vector3 K_child = Vector3::Zero();
  double m_child = 0.0;
  Vector3 h_child = Vector3::Zero();  // subtree first moment m c
  Vector3 F_child = Vector3::Zero();  // subtree bias wrench (full)
  Vector3 N_child = Vector3::Zero();
  for (int i = nb - 1; i > 0; --i) {
    const int p = model.parents[i];
    const bool chain_child = i + 1 < nb && model.parents[i + 1] == i;
    Vector3 L = data.f[i].head<3>();
    Vector3 K = data.f[i].tail<3>();
    double m = data.composite_mass[i];
    Vector3 h = data.composite_first_moment[i];
    Vector3 F;
    Vector3 N;
    if constexpr (full) {
      F = data.bias_f[i].head<3>();
      N = data.bias_f[i].tail<3>();
    }
    if (chain_child) {
      L += L_child;
      K += K_child;
      m += m_child;
      h += h_child;
      if constexpr (full) {
        F += F_child;
        N += N_child;
      }
    }
    data.f[i].head<3>() = L;
    data.f[i].tail<3>() = K;
    data.composite_mass[i] = m;
    data.composite_first_moment[i] = h;
    const Vector3 s_lin = data.S[i].head<3>();
    const Vector3 s_ang = data.S[i].tail<3>();
    const Vector3 v_O = data.v[p].head<3>();
    const Vector3 w = data.v[p].tail<3>();
    data.momentum[i - 1] = s_lin.dot(L) + s_ang.dot(K);  // p_i = S_i^T H_i
    // (C^T q_dot)_i = dT/dq_i. Moving joint i rotates the whole subtree: with world-frame
    // inertias dI_k/dq_i = S_i x* I_k - I_k S_i x, and dv_k/dq_i = S_i x (v_k - v_p); the
    // v_k terms cancel, leaving -S_i^T (v_p x* H_i), with v x* [L; K] = [w x L; v_O x L + w x K].
    data.coriolis_transpose_dq[i - 1] =
        -(s_lin.dot(w.cross(L)) + s_ang.dot(v_O.cross(L) + w.cross(K)));
    // g_i = -S_i^T [m g; h x g] (the subtree's weight)
    data.gravity_torque[i - 1] = -(s_lin.dot(m * g) + s_ang.dot(h.cross(g)));
    if constexpr (full) {
      data.bias_f[i].head<3>() = F;
      data.bias_f[i].tail<3>() = N;
      data.tau[i - 1] = s_lin.dot(F) + s_ang.dot(N);  // c_i = S_i^T f_i  (f_i: the subtree's)
    }
    if (p == i - 1) {
      L_child = L;
      K_child = K;
      m_child = m;
      h_child = h;
      if constexpr (full) {
        F_child = F;
        N_child = N;
      }
    } else {
      data.f[p].head<3>() += L;
      data.f[p].tail<3>() += K;
      data.composite_mass[p] += m;
      data.composite_first_moment[p] += h;
      if constexpr (full) {
        data.bias_f[p].head<3>() += F;
        data.bias_f[p].tail<3>() += N;
      }
      L_child.setZero();
      K_child.setZero();
      m_child = 0.0;
      h_child.setZero();
      F_child.setZero();
      N_child.setZero();
    }
  }
  if (nb > 1 && model.parents[1] == 0) {
    data.f[0].head<3>() += L_child;
    data.f[0].tail<3>() += K_child;
    data.composite_mass[0] += m_child;
    data.composite_first_moment[0] += h_child;
    if constexpr (full) {
      data.bias_f[0].head<3>() += F_child;
      data.bias_f[0].tail<3>() += N_child;
    }
  }
  if constexpr (full) data.root_wrench_W = data.bias_f[0];
  detail::add_armature_times(model, dq, data.momentum);  // p = (B_links + I_a) q_dot
}

}  // namespace

void momentum_terms(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                    const Eigen::Ref<const VectorX>& dq) {
  detail::check_data("momentum_terms", model, data);
  detail::check_joint_vector("momentum_terms", "q", q.size(), model);
  detail::check_joint_vector("momentum_terms", "dq", dq.size(), model);
  momentum_pass<false>(model, data, q, dq);
}

void momentum_and_bias_terms(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq) {
  detail::check_data("momentum_and_bias_terms", model, data);
  detail::check_joint_vector("momentum_and_bias_terms", "q", q.size(), model);
  detail::check_joint_vector("momentum_and_bias_terms", "dq", dq.size(), model);
  momentum_pass<true>(model, data, q, dq);
}

}  // namespace extwrench
