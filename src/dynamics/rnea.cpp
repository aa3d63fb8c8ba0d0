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
  for (int i = nb - 1; i > 0; --i) {
    data.tau[i - 1] = data.S[i].dot(data.f[i]);
    data.f[model.parents[i]] += data.f[i];
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
  data.a[0].head<3>() = -model.gravity;  // gravity trick: the base accelerates with -g (SPEC 3)
  {
    // Link 0 is at rest in the world frame: f_0 = [m (-g); c x m (-g)].
    const Inertia& inertia = model.bodies[0].inertia;
    const Vector3 F = -inertia.mass * model.gravity;
    data.f[0] << F, inertia.com.cross(F);
  }
  for (int i = 1; i < nb; ++i) {
    const int p = model.parents[i];
    detail::joint_kinematics(model.joints[i], data.placement_axis[i], data.placement_sign[i],
                             data.X_WB[p], q[i - 1], data.X_WB[i], data.S[i]);
    const Vector6& s = data.S[i];
    const Vector6 vj = s * dq[i - 1];
    data.v[i] = data.v[p] + vj;
    // a_i = a_p + S q_ddot + S_dot q_dot, with S_dot = v_p x S (S is fixed in the parent).
    data.a[i] = data.a[p] + s * ddq[i - 1] + detail::cross_motion(data.v[p], vj);
    // (7)-(8) about the CoM c: F = m c_ddot, N_c = I_c w_dot + w x I_c w (body axes, rotated
    // back), then moved to the world origin: f_i = [F; N_c + c x F] (= I_i a_i + v_i x* I_i v_i).
    const Inertia& inertia = model.bodies[i].inertia;
    const Pose& X = data.X_WB[i];
    const Vector3 c = X.act(inertia.com);
    const auto w = detail::ang(data.v[i]);
    const auto w_dot = detail::ang(data.a[i]);
    // c_ddot = a_O + w_dot x c + w x (v_O + w x c): the spatial acceleration at the world origin
    // turned into the classical acceleration of the body point at c.
    const Vector3 v_c = detail::lin(data.v[i]) + w.cross(c);
    const Vector3 F = inertia.mass * (detail::lin(data.a[i]) + w_dot.cross(c) + w.cross(v_c));
    const Vector3 w_B = X.rotation.transpose() * w;
    const Vector3 w_dot_B = X.rotation.transpose() * w_dot;
    const Vector3 N_B = inertia.inertia_com * w_dot_B + w_B.cross(inertia.inertia_com * w_B);
    data.f[i].head<3>() = F;
    data.f[i].tail<3>().noalias() = X.rotation * N_B;
    data.f[i].tail<3>() += c.cross(F);
  }
  return backward_pass(model, data, external);
}

const VectorX& rnea_no_kinematics(const Model& model, Data& data,
                                  const Eigen::Ref<const VectorX>& dq,
                                  const Eigen::Ref<const VectorX>& ddq,
                                  std::span<const ExternalWrench> external, bool with_gravity) {
  const int nb = model.num_bodies();
  // Forward pass. Gravity trick: the base accelerates with -g (SPEC 3).
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
    const Vector6 hi = detail::inertia_times(data.mass[i], data.first_moment_W[i],
                                             data.inertia_O_W[i], data.v[i]);
    data.f[i] = detail::inertia_times(data.mass[i], data.first_moment_W[i], data.inertia_O_W[i],
                                      data.a[i]) +
                detail::cross_force(data.v[i], hi);
  }
  return backward_pass(model, data, external);
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
  const Vector6 w = sensor_reading_world(data, X_WS.translation);
  Vector6 out;
  out.head<3>().noalias() = X_WS.rotation.transpose() * w.head<3>();
  out.tail<3>().noalias() = X_WS.rotation.transpose() * w.tail<3>();
  return out;
}

const VectorX& bias_torques(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                            const Eigen::Ref<const VectorX>& dq) {
  forward_kinematics(model, data, q);
  data.tmp_n.setZero();
  return rnea_no_kinematics(model, data, dq, data.tmp_n, {}, true);
}

const VectorX& gravity_torques(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  forward_kinematics(model, data, q);
  data.tmp_n.setZero();
  rnea_no_kinematics(model, data, data.tmp_n, data.tmp_n, {}, true);
  data.gravity_torque = data.tau;
  return data.gravity_torque;
}

}  // namespace extwrench
