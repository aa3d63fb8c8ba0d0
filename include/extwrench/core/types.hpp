// Basic linear-algebra types and small spatial helpers shared by every module.
//
// Conventions (stated once, see docs/conventions.md):
//  - 6D vectors are ordered [linear; angular], as F/T sensors, Pinocchio and KDL do.
//  - A Pose X_AB maps coordinates in frame B to frame A: p_A = R_AB p_B + p_AB.
//  - Spatial quantities in dynamics::Data are expressed in the world (root) frame, about the
//    world origin, unless their name says otherwise.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace extwrench {

using Vector3 = Eigen::Vector3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix3 = Eigen::Matrix3d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using VectorX = Eigen::VectorXd;
using MatrixX = Eigen::MatrixXd;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using Matrix3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

/// A per-joint option given as one value for all joints or one per joint: its n values (a value
/// of any other size is returned as it is; the options' validate() rejects it).
[[nodiscard]] inline VectorX per_joint(const VectorX& v, int n) {
  return v.size() == 1 ? VectorX::Constant(n, v[0]) : v;
}

/// Skew-symmetric matrix S(v) such that S(v) w = v × w.
inline Matrix3 skew(const Vector3& v) {
  Matrix3 s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

/// Rigid transform X_AB (pose of frame B in frame A).
struct Pose {
  Matrix3 rotation = Matrix3::Identity();  ///< R_AB
  Vector3 translation = Vector3::Zero();   ///< p_AB: origin of B in A

  static Pose identity() { return {}; }

  /// URDF convention: fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)).
  static Pose from_xyz_rpy(const Vector3& xyz, const Vector3& rpy) {
    Pose x;
    x.rotation = (Eigen::AngleAxisd(rpy.z(), Vector3::UnitZ()) *
                  Eigen::AngleAxisd(rpy.y(), Vector3::UnitY()) *
                  Eigen::AngleAxisd(rpy.x(), Vector3::UnitX()))
                     .toRotationMatrix();
    x.translation = xyz;
    return x;
  }

  /// X_AC = X_AB * X_BC
  Pose operator*(const Pose& other) const {
    Pose x;
    x.rotation.noalias() = rotation * other.rotation;
    x.translation.noalias() = rotation * other.translation;
    x.translation += translation;
    return x;
  }

  /// Point given in B, returned in A.
  Vector3 act(const Vector3& p_B) const { return rotation * p_B + translation; }

  Pose inverse() const {
    Pose x;
    x.rotation = rotation.transpose();
    x.translation.noalias() = -(x.rotation * translation);
    return x;
  }

  bool is_approx(const Pose& other, double tol = 1e-12) const {
    return rotation.isApprox(other.rotation, tol) &&
           (translation - other.translation).norm() <= tol * (1.0 + translation.norm());
  }
};

/// Rotation matrix to fixed-axis roll, pitch, yaw (URDF convention: R = Rz(yaw) Ry(pitch)
/// Rx(roll)). Roll is read from the middle row of Rz(yaw)ᵀ R, which is Ry(pitch) Rx(roll)'s
/// (0, cos roll, −sin roll) whatever the pitch, not from R's last row: near pitch = ±π/2 that
/// row's entries, and the first column's that give yaw, are rounding-sized, and roll and yaw
/// read each on its own did not compose back to R (a sensor at pitch π/2 written 0.04 rad off).
/// At the lock itself (the first column's entries below 1e-15, rounding) yaw is 0 and roll takes
/// the whole turn about the vertical. Never -0: atan2 of a -0 entry gives -0, which text would
/// carry
/// ("-0") although reading it back gives the same rotation with a +0 entry, so written poses
/// would not be a fixed point (+ 0.0 makes it +0).
inline Vector3 rpy_from_rotation(const Matrix3& r) {
  const double horizontal = std::hypot(r(0, 0), r(1, 0));  // |cos pitch|
  const double pitch = std::atan2(-r(2, 0), horizontal);
  const double yaw = horizontal < 1e-15 ? 0.0 : std::atan2(r(1, 0), r(0, 0));
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double roll = std::atan2(s * r(0, 2) - c * r(1, 2), c * r(1, 1) - s * r(0, 1));
  return {roll + 0.0, pitch + 0.0, yaw + 0.0};
}

}  // namespace extwrench
