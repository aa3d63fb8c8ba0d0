// Forward kinematics and Jacobians.
#pragma once

#include "extwrench/dynamics/data.hpp"

namespace extwrench {

/// Poses of all bodies (data.X_WB), joint motion subspaces (data.S) and world-frame mass
/// properties. q: (n). Every other algorithm calls it first.
void forward_kinematics(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q);

/// Poses (data.X_WB) and joint motion subspaces (data.S) only: forward_kinematics without the
/// world-frame mass properties, bit for bit the same poses. Enough for frame_pose and the
/// Jacobians (about half the cost of forward_kinematics). q: (n).
void forward_poses(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q);

/// The world-frame mass properties of forward_kinematics (data.mass, data.first_moment_W,
/// data.inertia_O_W) from the poses already in data: for code that ran momentum_terms or rnea
/// (which compute poses but do not need these) and then wants crba_no_kinematics or
/// rnea_no_kinematics at the same q.
void world_mass_properties(const Model& model, Data& data);

/// Pose of a named frame in the world, after forward_kinematics or forward_poses.
[[nodiscard]] Pose frame_pose(const Model& model, const Data& data, int frame);

/// Jacobian of a point rigidly attached to body `body`, after forward_kinematics or
/// forward_poses:
/// J (6 x n) = [J_v; J_w], J_v maps q_dot to the point's linear velocity, J_w to the body's
/// angular velocity, both in world-aligned axes (the point is p_W, given in the world frame).
/// Columns of joints that are not ancestors of the body are zero. Writes into `J`, which must
/// be 6 x n (no allocation).
void point_jacobian(const Model& model, const Data& data, int body, const Vector3& p_W,
                    Eigen::Ref<Matrix6X> J);

/// Jacobian of the body frame's origin (point_jacobian at the body origin), into data.J.
const Matrix6X& body_jacobian(const Model& model, Data& data, int body);

/// cond(J) = σ_max / σ_min of J (6 × l), the Jacobian of the origin O_l of body l, world frame,
/// SI units: the "condition number of J of O_6" of the paper's Fig. 10 when l = 6. After
/// forward_poses (or forward_kinematics); NaN for body <= 0, +inf when J is singular. From the
/// eigenvalues of J's Gram matrix while κ < 1e6, else (and beyond 64 joints) from an SVD, which
/// allocates: not for the real-time path.
[[nodiscard]] double jacobian_condition(const Model& model, const Data& data, int body);

}  // namespace extwrench
