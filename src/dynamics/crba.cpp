#include "extwrench/dynamics/crba.hpp"

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

const MatrixX& crba(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  forward_kinematics(model, data, q);
  return crba_no_kinematics(model, data);
}

bool forward_dynamics(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q,
                      const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& tau) {
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
