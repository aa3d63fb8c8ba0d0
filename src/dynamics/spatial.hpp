// Private spatial-algebra helpers of the dynamics algorithms. Everything is in world axes about
// the world origin, [linear; angular]; only 3-vector operations, so nothing is allocated and no
// 6x6 matrix is formed on the hot path.
#pragma once

#include "extwrench/core/types.hpp"

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

}  // namespace extwrench::detail
