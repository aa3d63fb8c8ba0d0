// Joint-space mass matrix, Coriolis matrix, generalized momentum, forward dynamics.
#pragma once

#include "extwrench/dynamics/data.hpp"

namespace extwrench {

/// Mass matrix B(q) (composite rigid body algorithm) into data.M, both triangles.
/// Runs forward_kinematics. q: (n).
const MatrixX& crba(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q);
/// As crba, for the q of the last forward_kinematics.
const MatrixX& crba_no_kinematics(const Model& model, Data& data);

/// Coriolis matrix C(q, dq) into data.C, the factorization with B_dot = C + C^T
/// (C = sum_k J_k^T (I_k J_dot_k + (v_k x*) I_k J_k)). Runs forward_kinematics.
const MatrixX& coriolis_matrix(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq);

/// Generalized momentum p = B(q) dq into data.momentum and C^T(q, dq) dq = dT/dq into
/// data.coriolis_transpose_dq, both in O(n) (SPEC 2), and g(q) into data.gravity_torque.
/// Computes the poses and motion subspaces (data.X_WB, data.S) but, unlike forward_kinematics,
/// not the world-frame mass properties (world_mass_properties adds them). These are the three
/// model terms of the momentum residual (4).
void momentum_terms(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                    const Eigen::Ref<const VectorX>& dq);
/// momentum_terms plus, in the same pass, what the forward dynamics at (q, q_dot) needs: the
/// world-frame mass properties (as forward_kinematics, for crba_no_kinematics) and the bias
/// torques c(q, q_dot) = C q_dot + g into data.tau with the matching ground wrench (q_ddot = 0)
/// into data.root_wrench_W (as bias_torques). One pass instead of three.
void momentum_and_bias_terms(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq);
/// As momentum_terms, for the q of the last forward_kinematics.
void momentum_terms_no_kinematics(const Model& model, Data& data,
                                  const Eigen::Ref<const VectorX>& dq);

/// Forward dynamics ddq = B^-1 (tau - c(q, dq)) into data.ddq (Cholesky of the mass matrix,
/// no allocation). Returns false if B is not positive definite.
[[nodiscard]] bool forward_dynamics(const Model& model, Data& data,
                                    const Eigen::Ref<const VectorX>& q,
                                    const Eigen::Ref<const VectorX>& dq,
                                    const Eigen::Ref<const VectorX>& tau);

}  // namespace extwrench
