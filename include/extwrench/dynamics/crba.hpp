// Joint-space mass matrix (composite rigid body algorithm) and forward dynamics.
#pragma once

#include "extwrench/dynamics/data.hpp"

namespace extwrench {

/// Mass matrix B(q) (composite rigid body algorithm) into data.M, both triangles. q: (n).
/// One fused pass: leaves the poses and motion subspaces of forward_poses in data (X_WB, S), but
/// not the world mass properties of forward_kinematics (data.mass, first_moment_W, inertia_O_W
/// are not updated; call world_mass_properties before a *_no_kinematics function that needs them).
const MatrixX& crba(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q);
/// As crba, for the q of the last forward_kinematics.
const MatrixX& crba_no_kinematics(const Model& model, Data& data);

/// Forward dynamics ddq = B^-1 (tau - c(q, dq)) into data.ddq (Cholesky of the mass matrix,
/// no allocation). Returns false if B is not positive definite.
[[nodiscard]] bool forward_dynamics(const Model& model, Data& data,
                                    const Eigen::Ref<const VectorX>& q,
                                    const Eigen::Ref<const VectorX>& dq,
                                    const Eigen::Ref<const VectorX>& tau);

}  // namespace extwrench
