// Generalized momentum and the other model terms of the momentum residual, in one O(n) pass.
#pragma once

#include "extwrench/dynamics/data.hpp"

namespace extwrench {

/// Generalized momentum p = B(q) dq into data.momentum and C^T(q, dq) dq = dT/dq into
/// data.coriolis_transpose_dq, both in O(n) (docs/algorithms.md), and g(q) into
/// data.gravity_torque. Computes the poses and motion subspaces (data.X_WB, data.S) but, unlike
/// forward_kinematics, not the world-frame mass properties (world_mass_properties adds them). These
/// are the three model terms of the momentum residual (4).
void momentum_terms(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                    const Eigen::Ref<const VectorX>& dq);
/// momentum_terms plus, in the same pass, what the forward dynamics at (q, q_dot) needs: the
/// world-frame mass properties (as forward_kinematics, for crba_no_kinematics) and the bias
/// torques c(q, q_dot) = C q_dot + g into data.tau with the matching ground wrench (q_ddot = 0)
/// into data.root_wrench_W (as bias_torques). One pass instead of three.
void momentum_and_bias_terms(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq);

}  // namespace extwrench
