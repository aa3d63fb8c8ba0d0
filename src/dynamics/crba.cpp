#include "extwrench/dynamics/crba.hpp"

#include "argument_checks.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "spatial.hpp"

namespace extwrench {

const MatrixX& crba_no_kinematics(const Model& model, Data& data) {
  const int nb = model.num_bodies();
  for (int i = 0; i < nb; ++i) {
    data.composite_mass[i] = data.mass[i];
    data.composite_first_moment[i] = data.first_moment_W[i];
    data.composite_inertia_O[i] = data.inertia_O_W[i];
  }
  for (int i = nb - 1; i > 0; --i) {
    const double m = data.composite_mass[i];
    const Vector3& h = data.composite_first_moment[i];
    const Matrix3& I_O = data.composite_inertia_O[i];
    const Vector6 F = detail::inertia_times(m, h, I_O, data.S[i]);
    // M_ij = S_j^T Ic_i S_i for j = i and every ancestor j of i.
    for (int j = i; j > 0; j = model.parents[j]) {
      const double mij = data.S[j].dot(F);
      data.M(i - 1, j - 1) = mij;
      data.M(j - 1, i - 1) = mij;
    }
    const int p = model.parents[i];
    data.composite_mass[p] += m;
    data.composite_first_moment[p] += h;
    data.composite_inertia_O[p] += I_O;
  }
  detail::add_armature_diagonal(model, data.M);
  return data.M;
}

namespace {

/// A * B and A * B^T for 3x3 matrices, column by column (each column one 2-double packet and one
/// double): the product's column loads then match the stores that wrote its operands. Eigen's
/// own 3x3 product stores 9 contiguous doubles in packets and reads columns at offsets 3 and 6
/// across two of them, which stalls store forwarding when the operand was just written (the
/// parent's rotation along a chain was a tenth of crba).
[[gnu::always_inline]] inline Matrix3 times(const Matrix3& A, const Matrix3& B) {
  Matrix3 C;
  for (int k = 0; k < 3; ++k) {
    C.col(k) = A.col(0) * B(0, k) + A.col(1) * B(1, k) + A.col(2) * B(2, k);
  }
  return C;
}
[[gnu::always_inline]] inline Matrix3 times_transpose(const Matrix3& A, const Matrix3& B) {
  Matrix3 C;
  for (int k = 0; k < 3; ++k) {
    C.col(k) = A.col(0) * B(k, 0) + A.col(1) * B(k, 1) + A.col(2) * B(k, 2);
  }
  return C;
}

/// A body's mass properties about the world origin from its pose (R, p), as
/// detail::world_mass_properties_of but from registers: h = m c_W, I_O = R I_c R^T + m (|c|^2 1 -
/// c c^T).
[[gnu::always_inline]] inline void world_mass_properties_at(const Inertia& inertia,
                                                            const Matrix3& R, const Vector3& p,
                                                            Vector3& h, Matrix3& I_O) {
  const Vector3 c_W =
      R.col(0) * inertia.com.x() + R.col(1) * inertia.com.y() + R.col(2) * inertia.com.z() + p;
  h = inertia.mass * c_W;
  I_O = times_transpose(times(R, inertia.inertia_com), R);
  const double hc = h.dot(c_W);
  for (int k = 0; k < 3; ++k) {
    I_O.col(k) -= h * c_W[k];
    I_O(k, k) += hc;
  }
}

}  // namespace

const MatrixX& crba(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  detail::check_data("crba", model, data);
  detail::check_joint_vector("crba", "q", q.size(), model);
  // forward_kinematics + crba_no_kinematics fused: each body's world mass properties go straight
  // into the composite arrays (no copy pass, no data.mass / first_moment_W / inertia_O_W), and
  // along a chain the child's composite is carried in registers.
  const int nb = model.num_bodies();
  // sin_cos_poly, not glibc's sincos (~11 ns per joint): within 2.3e-16 of it.
  detail::sin_cos_poly_n(q.data(), data.sin_q.data(), data.cos_q.data(), nb - 1);
  data.X_WB[0] = Pose{};
  data.S[0].setZero();
  for (int i = 1; i < nb; ++i) {
    // The parent's pose from memory, not carried in locals: the compiler spilled a carried 3x3
    // in 16-byte packets and read its columns across two of them (a store-forwarding stall,
    // a tenth of crba); stored column by column below, each load here meets one store.
    const Matrix3& R_p = data.X_WB[model.parents[i]].rotation;
    const Vector3& O_p = data.X_WB[model.parents[i]].translation;
    // detail::joint_kinematics with column-wise products (times).
    const Joint& joint = model.joints[i];
    const Matrix3 E = data.rotation_const[i] + data.cos_q[i - 1] * data.rotation_cos[i] +
                      data.sin_q[i - 1] * data.rotation_sin[i];
    const Matrix3 R = times(R_p, E);
    const Vector3& t = joint.placement.translation;
    const Vector3& a = data.axis_P[i];
    Vector3 O = R_p.col(0) * t.x() + R_p.col(1) * t.y() + R_p.col(2) * t.z() + O_p;
    Vector3 s_ang = R_p.col(0) * a.x() + R_p.col(1) * a.y() + R_p.col(2) * a.z();
    Vector3 s_lin;
    if (joint.type == JointType::kRevolute) {
      s_lin = O.cross(s_ang);  // the body point at the world origin moves with O_i x axis
    } else {
      O += s_ang * q[i - 1];
      s_lin = s_ang;  // prismatic: S = [axis; 0]
      s_ang.setZero();
    }
    for (int k = 0; k < 3; ++k) data.X_WB[i].rotation.col(k) = R.col(k);
    data.X_WB[i].translation = O;
    data.S[i].head<3>() = s_lin;
    data.S[i].tail<3>() = s_ang;
    const Inertia& inertia = model.bodies[i].inertia;
    data.composite_mass[i] = inertia.mass;
    world_mass_properties_at(inertia, R, O, data.composite_first_moment[i],
                             data.composite_inertia_O[i]);
  }
  // Leaf to root; link 0's composite is not needed for B. The composite is carried as scalars
  // (m, h, the 6 entries of the symmetric I_O): as Eigen 3x3 / 6-vector temporaries they were
  // spilled in 16-byte packets and read back across two stores (columns of 3), which stalls
  // store forwarding; that was a third of this loop.
  double cm = 0.0, chx = 0.0, chy = 0.0, chz = 0.0;  // the chain child's composite, else zero
  double cxx = 0.0, cyy = 0.0, czz = 0.0, cxy = 0.0, cxz = 0.0, cyz = 0.0;
  for (int i = nb - 1; i > 0; --i) {
    const Vector3& hi = data.composite_first_moment[i];
    const Matrix3& Ii = data.composite_inertia_O[i];
    const double m = data.composite_mass[i] + cm;
    const double hx = hi.x() + chx, hy = hi.y() + chy, hz = hi.z() + chz;
    const double xx = Ii(0, 0) + cxx, yy = Ii(1, 1) + cyy, zz = Ii(2, 2) + czz;
    const double xy = Ii(1, 0) + cxy, xz = Ii(2, 0) + cxz, yz = Ii(2, 1) + cyz;
    // F = Ic_i S_i = [m v - h x w; h x v + I_O w] with S_i = [v; w].
    const Vector6& S = data.S[i];
    const double vx = S[0], vy = S[1], vz = S[2], wx = S[3], wy = S[4], wz = S[5];
    const double f0 = m * vx - (hy * wz - hz * wy);
    const double f1 = m * vy - (hz * wx - hx * wz);
    const double f2 = m * vz - (hx * wy - hy * wx);
    const double f3 = (hy * vz - hz * vy) + (xx * wx + xy * wy + xz * wz);
    const double f4 = (hz * vx - hx * vz) + (xy * wx + yy * wy + yz * wz);
    const double f5 = (hx * vy - hy * vx) + (xz * wx + yz * wy + zz * wz);
    // B_ij = S_j^T Ic_i S_i for j = i and every ancestor j of i.
    for (int j = i; j > 0; j = model.parents[j]) {
      const Vector6& Sj = data.S[j];
      const double mij =
          (Sj[0] * f0 + Sj[1] * f1 + Sj[2] * f2) + (Sj[3] * f3 + Sj[4] * f4 + Sj[5] * f5);
      data.M(i - 1, j - 1) = mij;
      data.M(j - 1, i - 1) = mij;
    }
    const int p = model.parents[i];
    if (p == i - 1) {
      cm = m, chx = hx, chy = hy, chz = hz;
      cxx = xx, cyy = yy, czz = zz, cxy = xy, cxz = xz, cyz = yz;
    } else {
      if (p > 0) {
        data.composite_mass[p] += m;
        data.composite_first_moment[p] += Vector3(hx, hy, hz);
        Matrix3& Ip = data.composite_inertia_O[p];
        Ip(0, 0) += xx, Ip(1, 1) += yy, Ip(2, 2) += zz;
        Ip(1, 0) += xy, Ip(2, 0) += xz, Ip(2, 1) += yz;
      }
      cm = chx = chy = chz = 0.0;
      cxx = cyy = czz = cxy = cxz = cyz = 0.0;
    }
  }
  detail::add_armature_diagonal(model, data.M);
  return data.M;
}

bool forward_dynamics(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                      const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& tau) {
  detail::check_data("forward_dynamics", model, data);
  detail::check_joint_vector("forward_dynamics", "q", q.size(), model);
  detail::check_joint_vector("forward_dynamics", "dq", dq.size(), model);
  detail::check_joint_vector("forward_dynamics", "tau", tau.size(), model);
  forward_kinematics(model, data, q);
  crba_no_kinematics(model, data);
  data.tmp_n.setZero();
  rnea_no_kinematics(model, data, dq, data.tmp_n, {}, true);
  data.mass_llt.compute(data.M);
  if (data.mass_llt.info() != Eigen::Success) return false;
  data.ddq = tau - data.tau;
  data.mass_llt.solveInPlace(data.ddq);
  return true;
}

}  // namespace extwrench
