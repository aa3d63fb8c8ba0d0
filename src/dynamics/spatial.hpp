// Private spatial-algebra helpers of the dynamics algorithms. Everything is in world axes about
// the world origin, [linear; angular]; only 3-vector operations, so nothing is allocated and no
// 6x6 matrix is formed on the hot path.
#pragma once

#include <cmath>

#include "extwrench/core/types.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::detail {

inline auto lin(Vector6& x) { return x.head<3>(); }
inline auto ang(Vector6& x) { return x.tail<3>(); }
inline auto lin(const Vector6& x) { return x.head<3>(); }
inline auto ang(const Vector6& x) { return x.tail<3>(); }

/// Motion cross product v x m (v = [v_O; w]): [w x m_v + v_O x m_w; w x m_w].
inline Vector6 cross_motion(const Vector6& v, const Vector6& m) {
  Vector6 out;
  out.head<3>() = ang(v).cross(lin(m)) + lin(v).cross(ang(m));
  out.tail<3>() = ang(v).cross(ang(m));
  return out;
}

/// Force cross product v x* f (f = [F; N]): [w x F; v_O x F + w x N].
inline Vector6 cross_force(const Vector6& v, const Vector6& f) {
  Vector6 out;
  out.head<3>() = ang(v).cross(lin(f));
  out.tail<3>() = lin(v).cross(lin(f)) + ang(v).cross(ang(f));
  return out;
}

/// Spatial inertia (about the world origin) applied to a motion: I v with mass m, first moment
/// h = m c and rotational inertia I_O about the origin: [m v_O - h x w; h x v_O + I_O w].
inline Vector6 inertia_times(double m, const Vector3& h, const Matrix3& inertia_O, const Vector6& v) {
  Vector6 out;
  out.head<3>() = m * lin(v) - h.cross(ang(v));
  out.tail<3>() = h.cross(lin(v)) + inertia_O * ang(v);
  return out;
}

/// The 6x6 matrix of inertia_times (used off the hot path, e.g. by the Coriolis matrix).
inline Matrix6 inertia_matrix(double m, const Vector3& h, const Matrix3& inertia_O) {
  Matrix6 out;
  out.topLeftCorner<3, 3>() = m * Matrix3::Identity();
  out.topRightCorner<3, 3>() = -skew(h);
  out.bottomLeftCorner<3, 3>() = skew(h);
  out.bottomRightCorner<3, 3>() = inertia_O;
  return out;
}

/// The 6x6 matrix of cross_force(v, .).
inline Matrix6 cross_force_matrix(const Vector6& v) {
  Matrix6 out = Matrix6::Zero();
  out.topLeftCorner<3, 3>() = skew(ang(v));
  out.bottomLeftCorner<3, 3>() = skew(lin(v));
  out.bottomRightCorner<3, 3>() = skew(ang(v));
  return out;
}

/// Rotation by `angle` about the unit `axis` (Rodrigues).
inline Matrix3 axis_rotation(const Vector3& axis, double angle) {
  const double s = std::sin(angle);
  const double c = std::cos(angle);
  const double t = 1.0 - c;
  const double x = axis.x(), y = axis.y(), z = axis.z();
  Matrix3 r;
  r << t * x * x + c, t * x * y - s * z, t * x * z + s * y,  //
      t * x * y + s * z, t * y * y + c, t * y * z - s * x,   //
      t * x * z - s * y, t * y * z + s * x, t * z * z + c;
  return r;
}

/// R * Rot(axis, angle) for a body whose joint frame has world rotation R (s = sin, c = cos).
/// A coordinate axis (+-x, +-y, +-z, the URDF/DH norm) only mixes two columns of R (12 flops
/// instead of Rodrigues plus a 3x3 product); any other axis takes the general path.
inline void rotate_about_axis(const Matrix3& R, const Vector3& axis, double s, double c,
                              Matrix3& out) {
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3;
    const int j = (k + 2) % 3;
    if (axis[i] == 0.0 && axis[j] == 0.0 && (axis[k] == 1.0 || axis[k] == -1.0)) {
      // Rot(e_k, q): column i -> c e_i + s e_j, column j -> -s e_i + c e_j (s flips with -e_k).
      const double sk = axis[k] * s;
      out.col(k) = R.col(k);
      out.col(i) = c * R.col(i) + sk * R.col(j);
      out.col(j) = c * R.col(j) - sk * R.col(i);
      return;
    }
  }
  const double t = 1.0 - c;
  const double x = axis.x(), y = axis.y(), z = axis.z();
  Matrix3 r;
  r << t * x * x + c, t * x * y - s * z, t * x * z + s * y,  //
      t * x * y + s * z, t * y * y + c, t * y * z - s * x,   //
      t * x * z - s * y, t * y * z + s * x, t * z * z + c;
  out.noalias() = R * r;
}

/// Pose X_WB of body i and its joint's motion subspace S_i (world, about the world origin),
/// from the parent's pose X_WP and q_i (placement_*: Data's classification of the placement).
inline void joint_kinematics(const Joint& joint, const std::array<int, 3>& placement_axis,
                             const Vector3& placement_sign, const Pose& X_WP, double qi, Pose& X_WB,
                             Vector6& S) {
  Matrix3 R_WJ;  // joint frame at q = 0
  if (placement_axis[0] >= 0) {
    for (int k = 0; k < 3; ++k) R_WJ.col(k) = placement_sign[k] * X_WP.rotation.col(placement_axis[k]);
  } else {
    R_WJ.noalias() = X_WP.rotation * joint.placement.rotation;
  }
  X_WB.translation.noalias() = X_WP.rotation * joint.placement.translation;
  X_WB.translation += X_WP.translation;
  // The URDF/DH norm is a coordinate axis: then axis_W is a column of R_WJ, no product.
  const Vector3& a = joint.axis;
  Vector3 axis_W;
  if (a.x() == 0.0 && a.y() == 0.0 && a.z() == 1.0) {
    axis_W = R_WJ.col(2);
  } else {
    axis_W.noalias() = R_WJ * a;
  }
  if (joint.type == JointType::kRevolute) {
    rotate_about_axis(R_WJ, joint.axis, std::sin(qi), std::cos(qi), X_WB.rotation);
    // Revolute about axis z through O_i: velocity of the body point at the world origin
    // is O_i x z q_dot.
    S << X_WB.translation.cross(axis_W), axis_W;
  } else {
    X_WB.rotation = R_WJ;
    X_WB.translation += axis_W * qi;
    S << axis_W, Vector3::Zero();
  }
}

/// Poses (data.X_WB) and motion subspaces (data.S) of all bodies: forward_kinematics without
/// the world-frame mass properties.
inline void poses_and_subspaces(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  const int nb = model.num_bodies();
  data.X_WB[0] = Pose{};
  data.S[0].setZero();
  for (int i = 1; i < nb; ++i) {
    joint_kinematics(model.joints[i], data.placement_axis[i], data.placement_sign[i],
                     data.X_WB[model.parents[i]], q[i - 1], data.X_WB[i], data.S[i]);
  }
}

}  // namespace extwrench::detail
