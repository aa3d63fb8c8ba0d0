#include "extwrench/dynamics/rnea.hpp"

#include "extwrench/dynamics/kinematics.hpp"
#include "spatial.hpp"

namespace extwrench {

const VectorX& rnea(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                    const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& ddq,
                    std::span<const ExternalWrench> external) {
  forward_kinematics(model, data, q);
  return rnea_no_kinematics(model, data, dq, ddq, external, true);
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
  // External wrenches: force at p plus pure moment, moved to the world origin (Remark 4).
  for (const ExternalWrench& w : external) {
    data.f[w.body].head<3>() -= w.force_W;
    data.f[w.body].tail<3>() -= w.moment_W + w.point_W.cross(w.force_W);
  }
  // Backward pass (9)-(12), down to i = 0: f_0 is what the ground applies to link 0.
  for (int i = nb - 1; i > 0; --i) {
    data.tau[i - 1] = data.S[i].dot(data.f[i]);
    data.f[model.parents[i]] += data.f[i];
  }
  data.root_wrench_W = data.f[0];
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
