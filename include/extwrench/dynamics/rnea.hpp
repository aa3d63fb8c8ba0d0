// Recursive Newton-Euler with external wrenches and the base iteration, and the terms built on
// it: bias and gravity torques, the Coriolis matrix, the base sensor reading (docs/algorithms.md).
#pragma once

#include <span>

#include "extwrench/dynamics/data.hpp"

namespace extwrench {

/// An external wrench acting on a body: a force applied at a point plus a pure moment,
/// all in the world frame.
struct ExternalWrench {
  int body = 0;                        ///< index of the body it acts on (0 = link 0)
  Vector3 force_W = Vector3::Zero();   ///< F_ext [N]
  Vector3 point_W = Vector3::Zero();   ///< application point p [m]
  Vector3 moment_W = Vector3::Zero();  ///< pure moment M_ext [N m]
};

/// Inverse dynamics tau = B(q) ddq + C(q, dq) dq + g(q) - sum_k J_k^T W_k, eqs. (7)-(12),
/// iterated down to link 0: data.root_wrench_W is f_0 (the wrench the ground applies to link 0,
/// about the world origin, link 0's own weight included). Works in each body's joint-aligned
/// frame (Data::aligned, its mass properties cached there) and forms no world pose: it leaves
/// data.tau, data.root_wrench_W and its scratch (data.w_J, a_J, f_J), not data.X_WB, S, v, a, f
/// (run forward_poses or forward_kinematics for those; with external wrenches it runs
/// forward_poses itself, to bring them into the body frames). q, dq, ddq: (n). Returns data.tau.
const VectorX& rnea(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                    const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& ddq,
                    std::span<const ExternalWrench> external = {});

/// As rnea, but after forward_kinematics was already run for this q (saves the pose pass).
const VectorX& rnea_no_kinematics(const Model& model, Data& data,
                                  const Eigen::Ref<const VectorX>& dq,
                                  const Eigen::Ref<const VectorX>& ddq,
                                  std::span<const ExternalWrench> external = {},
                                  bool with_gravity = true);

/// What the robot discharges onto a base sensor at pose X_WS (docs/method.md, "Newton-Euler and the
/// base sensor": f_m = -f_0, n_m = -n_0 about O_s), in the sensor frame: [f_m; n_m], moment about
/// the sensor origin. Uses data.root_wrench_W from the last rnea.
[[nodiscard]] Vector6 sensor_reading(const Data& data, const Pose& X_WS);

/// The same reading expressed in the world frame (moment still about O_s).
[[nodiscard]] Vector6 sensor_reading_world(const Data& data, const Vector3& p_WS);

/// Bias torques c(q, dq) = C(q, dq) dq + g(q) into data.tau: rnea at ddq = 0 (it leaves what
/// rnea leaves, not the world mass properties of forward_kinematics). q, dq: (n).
const VectorX& bias_torques(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                            const Eigen::Ref<const VectorX>& dq);

/// Gravity torques g(q) into data.gravity_torque: an O(n) pass over the subtrees' masses and
/// first moments in body frames (docs/algorithms.md), without velocities, inertia tensors or
/// world poses. Writes only data.gravity_torque and the scratch gravity_B, gravity_lin_B,
/// gravity_moment_B, composite_mass, composite_first_moment_B, sin_q, cos_q (not data.tau, X_WB
/// or S). Armature does not enter g. q: (n).
const VectorX& gravity_torques(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q);

/// Coriolis matrix C(q, dq) into data.C, the factorization with B_dot = C + C^T
/// (C = sum_k J_k^T (I_k J_dot_k + (v_k x*) I_k J_k)). Runs forward_kinematics.
const MatrixX& coriolis_matrix(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq);

}  // namespace extwrench
