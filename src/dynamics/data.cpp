#include "extwrench/dynamics/data.hpp"

#include <cmath>

namespace extwrench {

Data::Data(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.num_bodies());
  const int n = model.nq();
  rotation_const.assign(nb, Matrix3::Identity());
  rotation_cos.assign(nb, Matrix3::Zero());
  rotation_sin.assign(nb, Matrix3::Zero());
  axis_P.assign(nb, Vector3::Zero());
  for (std::size_t i = 1; i < nb && i < model.joints.size(); ++i) {
    const Joint& joint = model.joints[i];
    const Matrix3& P = joint.placement.rotation;
    const Vector3& a = joint.axis;
    axis_P[i] = P * a;
    if (joint.type == JointType::kRevolute) {
      const Matrix3 aaT = a * a.transpose();
      rotation_const[i] = P * aaT;
      rotation_cos[i] = P * (Matrix3::Identity() - aaT);
      rotation_sin[i] = P * skew(a);
    } else {
      rotation_const[i] = P;
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
  sin_q = VectorX::Zero(n);
  cos_q = VectorX::Zero(n);
  // Sized by a factorization rather than by copying LLT(n), whose ComputationInfo is left
  // uninitialized by Eigen (UBSan: invalid enum load in the copy).
  mass_llt.compute(MatrixX::Identity(n, n));
}

}  // namespace extwrench
