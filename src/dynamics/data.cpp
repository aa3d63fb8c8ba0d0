#include "extwrench/dynamics/data.hpp"

#include <cmath>

namespace extwrench {

namespace {

/// Column k of R is sign[k] e_{axis[k]} (entries within 1e-12 of 0 or ±1: rpy of ±π/2 leaves
/// cos(π/2) ≈ 6e-17, which the shuffle then treats as 0). axis[0] = −1 when R is general.
void classify_rotation(const Matrix3& R, std::array<int, 3>& axis, Vector3& sign) {
  constexpr double kTol = 1e-12;
  axis = {-1, -1, -1};
  sign.setZero();
  std::array<int, 3> found{-1, -1, -1};
  for (int k = 0; k < 3; ++k) {
    for (int r = 0; r < 3; ++r) {
      const double e = R(r, k);
      if (std::abs(std::abs(e) - 1.0) <= kTol) {
        if (found[k] >= 0) return;
        found[k] = r;
        sign[k] = e > 0.0 ? 1.0 : -1.0;
      } else if (std::abs(e) > kTol) {
        return;
      }
    }
    if (found[k] < 0) return;
  }
  if (found[0] == found[1] || found[0] == found[2] || found[1] == found[2]) return;
  axis = found;
}

}  // namespace

Data::Data(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.num_bodies());
  const int n = model.nq();
  placement_axis.assign(nb, {-1, -1, -1});
  placement_sign.assign(nb, Vector3::Zero());
  axis_index.assign(nb, -1);
  axis_sign.assign(nb, 0.0);
  for (std::size_t i = 1; i < nb && i < model.joints.size(); ++i) {
    const Joint& joint = model.joints[i];
    classify_rotation(joint.placement.rotation, placement_axis[i], placement_sign[i]);
    for (int k = 0; k < 3; ++k) {
      const Vector3& a = joint.axis;
      if (std::abs(a[k]) == 1.0 && a[(k + 1) % 3] == 0.0 && a[(k + 2) % 3] == 0.0) {
        axis_index[i] = k;
        axis_sign[i] = a[k];
      }
    }
  }
  X_WB.assign(nb, Pose{});
  S.assign(nb, Vector6::Zero());
  mass.assign(nb, 0.0);
  first_moment_W.assign(nb, Vector3::Zero());
  inertia_O_W.assign(nb, Matrix3::Zero());
  v.assign(nb, Vector6::Zero());
  a.assign(nb, Vector6::Zero());
  f.assign(nb, Vector6::Zero());
  h.assign(nb, Vector6::Zero());
  bias_f.assign(nb, Vector6::Zero());
  composite_mass.assign(nb, 0.0);
  composite_first_moment.assign(nb, Vector3::Zero());
  composite_inertia_O.assign(nb, Matrix3::Zero());
  Ic.assign(nb, Matrix6::Zero());
  Bc.assign(nb, Matrix6::Zero());
  Sdot.assign(nb, Vector6::Zero());
  tau = VectorX::Zero(n);
  M = MatrixX::Zero(n, n);
  C = MatrixX::Zero(n, n);
  momentum = VectorX::Zero(n);
  coriolis_transpose_dq = VectorX::Zero(n);
  gravity_torque = VectorX::Zero(n);
  ddq = VectorX::Zero(n);
  J = Matrix6X::Zero(6, n);
  tmp_n = VectorX::Zero(n);
  // Sized by a factorization rather than by copying LLT(n), whose ComputationInfo is left
  // uninitialized by Eigen (UBSan: invalid enum load in the copy).
  mass_llt.compute(MatrixX::Identity(n, n));
}

}  // namespace extwrench
