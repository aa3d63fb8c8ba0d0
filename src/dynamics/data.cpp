#include "extwrench/dynamics/data.hpp"

namespace extwrench {

Data::Data(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.num_bodies());
  const int n = model.nq();
  X_WB.assign(nb, Pose{});
  S.assign(nb, Vector6::Zero());
  mass.assign(nb, 0.0);
  first_moment_W.assign(nb, Vector3::Zero());
  inertia_O_W.assign(nb, Matrix3::Zero());
  v.assign(nb, Vector6::Zero());
  a.assign(nb, Vector6::Zero());
  f.assign(nb, Vector6::Zero());
  h.assign(nb, Vector6::Zero());
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
