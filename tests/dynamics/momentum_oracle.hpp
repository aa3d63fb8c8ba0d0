// The test oracle for momentum_terms: the same three terms (B q_dot, C^T q_dot, g) written plainly
// with 6-vectors over the world-frame mass properties of forward_kinematics, without the fused
// pass's register carrying, so that the library's momentum pass is checked against a second,
// straightforward implementation.
#pragma once

#include "extwrench/dynamics/data.hpp"

namespace extwrench::test {

/// momentum_terms for the q of the last forward_kinematics on `data`: writes data.momentum,
/// data.coriolis_transpose_dq and data.gravity_torque (and uses data.v, h, f, composite_* as
/// scratch).
inline void momentum_terms_oracle(const Model& model, Data& data,
                                  const Eigen::Ref<const VectorX>& dq) {
  // I v about the world origin: [m v_O - h x w; h x v_O + I_O w].
  const auto inertia_times = [](double m, const Vector3& h, const Matrix3& I_O, const Vector6& v) {
    Vector6 out;
    out << m * v.head<3>() - h.cross(v.tail<3>()), h.cross(v.head<3>()) + I_O * v.tail<3>();
    return out;
  };
  // v x* f = [w x F; v_O x F + w x N].
  const auto cross_force = [](const Vector6& v, const Vector6& f) {
    Vector6 out;
    out << v.tail<3>().cross(f.head<3>()),
        v.head<3>().cross(f.head<3>()) + v.tail<3>().cross(f.tail<3>());
    return out;
  };
  const int nb = model.num_bodies();
  const Vector3& g = model.gravity;
  data.v[0].setZero();
  for (int i = 1; i < nb; ++i) data.v[i] = data.v[model.parents[i]] + data.S[i] * dq[i - 1];
  // Backward accumulation over subtrees, reusing f as the subtree momentum H_i.
  for (int i = 0; i < nb; ++i) {
    data.h[i] = inertia_times(data.mass[i], data.first_moment_W[i], data.inertia_O_W[i], data.v[i]);
    data.f[i] = data.h[i];  // H_i = sum of h_k over sub(i)
    data.composite_mass[i] = data.mass[i];
    data.composite_first_moment[i] = data.first_moment_W[i];
  }
  for (int i = nb - 1; i > 0; --i) {
    const int p = model.parents[i];
    const Vector6& s = data.S[i];
    // p_i = S_i^T H_i  (generalized momentum B q_dot)
    data.momentum[i - 1] = s.dot(data.f[i]);
    // (C^T q_dot)_i = dT/dq_i. Moving joint i rotates the whole subtree: with world-frame
    // inertias dI_k/dq_i = S_i x* I_k - I_k S_i x, and dv_k/dq_i = S_i x (v_k - v_p); the
    // v_k terms cancel, leaving dT/dq_i = -S_i^T (v_p x* H_i).
    data.coriolis_transpose_dq[i - 1] = -s.dot(cross_force(data.v[p], data.f[i]));
    // g_i = S_i^T [-m_c g; -h_c x g]  (composite weight of the subtree)
    const double mc = data.composite_mass[i];
    const Vector3& hc = data.composite_first_moment[i];
    data.gravity_torque[i - 1] = -(s.head<3>().dot(mc * g) + s.tail<3>().dot(hc.cross(g)));
    data.f[p] += data.f[i];
    data.composite_mass[p] += mc;
    data.composite_first_moment[p] += hc;
  }
}

}  // namespace extwrench::test
