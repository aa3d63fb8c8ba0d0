// Private spatial-algebra helpers of the dynamics algorithms. Everything is in world axes about
// the world origin, [linear; angular]; only 3-vector operations, so nothing is allocated and no
// 6x6 matrix is formed on the hot path.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include "extwrench/core/types.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::detail {

inline auto lin(Vector6& x) { return x.head<3>(); }
inline auto ang(Vector6& x) { return x.tail<3>(); }
inline auto lin(const Vector6& x) { return x.head<3>(); }
inline auto ang(const Vector6& x) { return x.tail<3>(); }

/// Armature (docs/model.md "Armature"): B_ii += a_i. A zero armature adds nothing at all (not
/// even +0.0), so a model without armature computes exactly what it did before.
inline void add_armature_diagonal(const Model& model, MatrixX& M) {
  const int nb = model.num_bodies();
  for (int i = 1; i < nb; ++i) {
    const double a = model.joints[static_cast<std::size_t>(i)].armature;
    if (a != 0.0) M(i - 1, i - 1) += a;
  }
}

/// out_i += a_i x_i for the joints with armature: tau += I_a q_ddot (RNEA), p += I_a q_dot
/// (momentum).
inline void add_armature_times(const Model& model, const Eigen::Ref<const VectorX>& x,
                               VectorX& out) {
  const int nb = model.num_bodies();
  for (int i = 1; i < nb; ++i) {
    const double a = model.joints[static_cast<std::size_t>(i)].armature;
    if (a != 0.0) out[i - 1] += a * x[i - 1];
  }
}

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
inline Vector6 inertia_times(double m, const Vector3& h, const Matrix3& inertia_O,
                             const Vector6& v) {
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

/// sin and cos of one angle in one libm call where the C library has one (glibc's sincos; GCC
/// does not always fuse separate std::sin and std::cos calls, and they are a large part of FK).
inline void sin_cos(double angle, double& s, double& c) {
#if defined(__GLIBC__)
  ::sincos(angle, &s, &c);
#else
  s = std::sin(angle);
  c = std::cos(angle);
#endif
}

namespace sin_cos_detail {
constexpr double kLargest = 1048576.0;              // 2^20: beyond, the reduction below loses bits
constexpr double kRoundShift = 6755399441055744.0;  // 1.5 * 2^52: x + it - it rounds x

/// The nearest multiple k of pi/2 and sin, cos of the rest r = angle - k pi/2 in [-pi/4, pi/4].
[[gnu::always_inline]] inline void reduced(double angle, double& k, double& sin_r, double& cos_r) {
  constexpr double kTwoOverPi = 0.636619772367581343075535053490057448;
  constexpr double kHalfPi1 = 1.57079625129699707031;  // pi/2 = kHalfPi1 + kHalfPi2 + kHalfPi3
  constexpr double kHalfPi2 = 7.54978941586159635335e-8;
  constexpr double kHalfPi3 = 5.39030285815811905290e-15;
  k = (angle * kTwoOverPi + kRoundShift) - kRoundShift;
  const double r = ((angle - k * kHalfPi1) - k * kHalfPi2) - k * kHalfPi3;
  // Cephes' sin.c coefficients, highest power first.
  constexpr double kSin[6] = {1.58962301576546568060e-10, -2.50507477628578072866e-8,
                              2.75573136213857245213e-6,  -1.98412698295895385996e-4,
                              8.33333333332211858878e-3,  -1.66666666666666307295e-1};
  constexpr double kCos[6] = {-1.13585365213876817300e-11, 2.08757008419747316778e-9,
                              -2.75573141792967388112e-7,  2.48015872888517045348e-5,
                              -1.38888888888730564116e-3,  4.16666666666665929218e-2};
  const double z = r * r;
  double ps = kSin[0];
  double pc = kCos[0];
  for (int i = 1; i < 6; ++i) {
    ps = ps * z + kSin[i];
    pc = pc * z + kCos[i];
  }
  sin_r = r + r * z * ps;
  cos_r = 1.0 - 0.5 * z + z * z * pc;
}
}  // namespace sin_cos_detail

/// sin and cos of one angle without a libm call, within 2.3e-16 of glibc's (2 ulp over 10^7
/// random angles up to 10^6 rad): the nearest multiple k of pi/2 is removed in three parts
/// (Cody-Waite; each k * part exact for |k| < 2^26), Cephes' minimax polynomials on
/// [-pi/4, pi/4], the quadrant from k mod 4. |angle| > 2^20 rad, inf and NaN go to sin_cos.
/// ~6 ns against ~11 ns for glibc's sincos here; every pose pass uses it (the libm calls were a
/// third of the gravity pass).

inline void sin_cos_poly(double angle, double& s, double& c) {
  if (!(std::abs(angle) <= sin_cos_detail::kLargest)) {
    sin_cos(angle, s, c);
    return;
  }
  double k, sin_r, cos_r;
  sin_cos_detail::reduced(angle, k, sin_r, cos_r);
  // angle = k pi/2 + r: quadrant j = k mod 4 (two's complement: also for negative k). Selected
  // with bit masks, not branches: the quadrant of arbitrary joint angles is unpredictable, and
  // GCC compiled the ?: selections to jumps. Same values (negation = flipping the sign bit).
  const auto j = static_cast<std::uint64_t>(static_cast<std::int64_t>(k));
  const std::uint64_t swap = 0 - (j & 1);  // all ones in odd quadrants
  const auto bs = std::bit_cast<std::uint64_t>(sin_r);
  const auto bc = std::bit_cast<std::uint64_t>(cos_r);
  const std::uint64_t s1 = (bs & ~swap) | (bc & swap);
  const std::uint64_t c1 = (bc & ~swap) | (bs & swap);
  s = std::bit_cast<double>(s1 ^ ((j & 2) << 62));
  c = std::bit_cast<double>(c1 ^ (((j + 1) & 2) << 62));
}

/// sin_cos_poly of n angles at once: the quadrant selected by arithmetic on 0/1 factors
/// (exact) instead of integer bit masks, so that the compiler runs two angles per SSE2
/// instruction. Same values as sin_cos_poly (a zero's sign aside). Any angle beyond 2^20 rad,
/// inf or NaN: every one goes through sin_cos_poly.
inline void sin_cos_poly_n(const double* angle, double* s, double* c, int n) {
  bool in_range = true;
  for (int j = 0; j < n; ++j) in_range &= std::abs(angle[j]) <= sin_cos_detail::kLargest;
  if (!in_range) {
    for (int j = 0; j < n; ++j) sin_cos_poly(angle[j], s[j], c[j]);
    return;
  }
  constexpr double kShift = sin_cos_detail::kRoundShift;
  for (int j = 0; j < n; ++j) {
    double k, sin_r, cos_r;
    sin_cos_detail::reduced(angle[j], k, sin_r, cos_r);
    // k mod 4 = k - 4 floor(k / 4); floor(k / 4) rounds k / 4 - 3/8 (k / 4 is a multiple of 1/4,
    // never a tie); then odd = quadrant mod 2 and half = quadrant >= 2 the same way.
    const double quadrant = k - 4.0 * (((k * 0.25 - 0.375) + kShift) - kShift);
    const double half = ((quadrant * 0.5 - 0.25) + kShift) - kShift;
    const double odd = quadrant - 2.0 * half;
    const double negate_cos = half + odd - 2.0 * half * odd;  // quadrants 1 and 2
    s[j] = ((1.0 - odd) * sin_r + odd * cos_r) * (1.0 - 2.0 * half);
    c[j] = ((1.0 - odd) * cos_r + odd * sin_r) * (1.0 - 2.0 * negate_cos);
  }
}

/// Rotation by the angle of sine s and cosine c about the unit `axis` (Rodrigues).
inline Matrix3 axis_rotation(const Vector3& axis, double s, double c) {
  const double t = 1.0 - c;
  const double x = axis.x(), y = axis.y(), z = axis.z();
  Matrix3 r;
  r << t * x * x + c, t * x * y - s * z, t * x * z + s * y,  //
      t * x * y + s * z, t * y * y + c, t * y * z - s * x,   //
      t * x * z - s * y, t * y * z + s * x, t * z * z + c;
  return r;
}

/// E(q) x = (E0 + c Ec + s Es) x as E0 x + c (Ec x) + s (Es x), without forming E: a 3x3
/// formed as one expression is computed in SSE packets that straddle its columns, and the
/// product after it reads them back through the stack, which stalls store forwarding (the
/// gravity pass took ~40 % longer that way). Each product here reads the constant columns from
/// memory.
[[gnu::always_inline]] inline Vector3 rotation_times(const Matrix3& E0, const Matrix3& Ec,
                                                     const Matrix3& Es, double c, double s,
                                                     const Vector3& x) {
  Vector3 out = E0 * x;
  out += c * (Ec * x);
  out += s * (Es * x);
  return out;
}

/// sin and cos of every joint coordinate into data.sin_q, data.cos_q, before a pose pass, by
/// sin_cos_poly_n (two angles per instruction, no libm call inside the chain, where each call
/// would push the pose and motion carried in registers out to the stack).
inline void joint_sin_cos(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  sin_cos_poly_n(q.data(), data.sin_q.data(), data.cos_q.data(), model.nq());
}

/// Pose (R, p) of body i and its joint's motion subspace S_i = [s_lin; s_ang] (world, about the
/// world origin), from the parent's pose X_WP, q_i and its sine and cosine in data (joint_sin_cos
/// first), into local variables: callers keep them in registers and store them once (reloading
/// vectors just written piecewise stalls the CPU's store forwarding). The joint's rotation is
/// Data's precomputed E_i(q) (no branch on the joint).
[[gnu::always_inline]] inline void joint_kinematics(const Model& model, const Data& data, int i,
                                                    const Pose& X_WP, double qi, Matrix3& R,
                                                    Vector3& p, Vector3& s_lin, Vector3& s_ang) {
  const Joint& joint = model.joints[i];
  const bool revolute = joint.type == JointType::kRevolute;
  const Matrix3 E = data.rotation_const[i] + data.cos_q[i - 1] * data.rotation_cos[i] +
                    data.sin_q[i - 1] * data.rotation_sin[i];
  R.noalias() = X_WP.rotation * E;
  p.noalias() = X_WP.rotation * joint.placement.translation;
  p += X_WP.translation;
  s_ang.noalias() = X_WP.rotation * data.axis_P[i];
  if (revolute) {
    // Revolute about the axis through O_i: the body point at the world origin moves with
    // O_i x axis q_dot.
    s_lin = p.cross(s_ang);
  } else {
    p += s_ang * qi;
    s_lin = s_ang;  // prismatic: S = [axis; 0]
    s_ang.setZero();
  }
}

/// joint_kinematics stored into data.X_WB[i] and data.S[i].
[[gnu::always_inline]] inline void joint_kinematics(const Model& model, Data& data, int i,
                                                    double qi) {
  Matrix3 R;
  Vector3 p;
  Vector3 s_lin;
  Vector3 s_ang;
  joint_kinematics(model, data, i, data.X_WB[model.parents[i]], qi, R, p, s_lin, s_ang);
  data.X_WB[i].rotation = R;
  data.X_WB[i].translation = p;
  data.S[i].head<3>() = s_lin;
  data.S[i].tail<3>() = s_ang;
}

/// Body i's motion from its parent's along joint i, in place on [v_O; w] (and, with
/// `with_acceleration`, [a_O; w_dot]): v_i = v_p + S q_dot, a_i = a_p + S q_ddot + v_p x S q_dot
/// (S_dot = v_p x S: S is fixed in the parent), with v x m = [w x m_v + v_O x m_w; w x m_w].
template <bool with_acceleration>
[[gnu::always_inline]] inline void propagate_motion(const Vector3& s_lin, const Vector3& s_ang,
                                                    double qd, double qdd, Vector3& v_O, Vector3& w,
                                                    Vector3& a_O, Vector3& w_dot) {
  const Vector3 vj_lin = s_lin * qd;
  const Vector3 vj_ang = s_ang * qd;
  if constexpr (with_acceleration) {
    a_O += s_lin * qdd + w.cross(vj_lin) + v_O.cross(vj_ang);
    w_dot += s_ang * qdd + w.cross(vj_ang);
  }
  v_O += vj_lin;
  w += vj_ang;
}

/// Eqs. (7)-(8) for one body about its CoM c (world), with the constant body-axes inertia I_c so
/// that no world inertia R I_c R^T is formed: F = m c_ddot, N_c = R (I_c w_dot_B + w_B x I_c w_B),
/// moved to the world origin: [F; N] = [F; N_c + c x F] (= I_i a_i + v_i x* I_i v_i). c_ddot =
/// a_O + w_dot x c + w x v_c turns the spatial acceleration at the world origin into the classical
/// acceleration of the body point at c; v_c is its velocity, w_B = R^T w, Iw_B = I_c w_B (the
/// caller has them: the momentum needs them too).
[[gnu::always_inline]] inline void newton_euler_about_com(const Inertia& inertia, const Matrix3& R,
                                                          const Vector3& c, const Vector3& v_c,
                                                          const Vector3& w, const Vector3& a_O,
                                                          const Vector3& w_dot, const Vector3& w_B,
                                                          const Vector3& Iw_B, Vector3& F,
                                                          Vector3& N) {
  F = inertia.mass * (a_O + w_dot.cross(c) + w.cross(v_c));
  const Vector3 w_dot_B = R.transpose() * w_dot;
  N = R * (inertia.inertia_com * w_dot_B + w_B.cross(Iw_B)) + c.cross(F);
}

/// Body i's mass properties about the world origin from its pose in data: m, h = m c_W and
/// I_O = R I_c R^T + m (|c|^2 1 - c c^T).
inline void world_mass_properties_of(const Model& model, Data& data, int i) {
  const Inertia& inertia = model.bodies[i].inertia;
  const Pose& X = data.X_WB[i];
  const Vector3 c_W = X.act(inertia.com);
  const double m = inertia.mass;
  data.mass[i] = m;
  const Vector3 h = m * c_W;
  data.first_moment_W[i] = h;
  // Symmetric: A = R I_c once, then only the lower triangle of A R^T + m (|c|^2 1 - c c^T).
  Matrix3 A;
  A.noalias() = X.rotation * inertia.inertia_com;
  const double mc2 = h.dot(c_W);
  Matrix3& I_O = data.inertia_O_W[i];
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col <= r; ++col) {
      const double e = A.row(r).dot(X.rotation.row(col)) - h[r] * c_W[col];
      I_O(r, col) = e;
      I_O(col, r) = e;
    }
    I_O(r, r) += mc2;
  }
}

/// Poses (data.X_WB) and motion subspaces (data.S) of all bodies: forward_kinematics without
/// the world-frame mass properties.
inline void poses_and_subspaces(const Model& model, Data& data,
                                const Eigen::Ref<const VectorX>& q) {
  const int nb = model.num_bodies();
  data.X_WB[0] = Pose{};
  data.S[0].setZero();
  joint_sin_cos(model, data, q);
  for (int i = 1; i < nb; ++i) {
    joint_kinematics(model, data, i, q[i - 1]);
  }
}

}  // namespace extwrench::detail
