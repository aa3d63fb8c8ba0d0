// Release from the base sensor (docs/estimator.md#release-from-the-sensor): stage 5b of
// ContactEstimator::update, apart from the stages so that detection and isolation stay short.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/contact_estimator.hpp"

namespace extwrench {

// 5b. With a base sensor, while a contact on link l (point p of the last sample) is declared:
// the external force the sensor gives at this instant without the residual's lag
// (docs/estimator.md#release-from-the-sensor). Route (b) predicts the base wrench with
// q̈̂ = q̈_free + B⁻¹ r, q̈_free = B⁻¹ (τ − τ_f − c), so F̂ decays with r after the push ends; with
// the true q̈ = q̈_free + B⁻¹ J_vᵀ F, G = ∂f̃_g/∂q̈ and H = ∂ñ_g/∂q̈ (about O_s), F̂(q̈) = F and
// (n_m − ñ_g)(q̈) = (p − p_s) × F give
//   (I + G B⁻¹ J_vᵀ) F = F̂ + G B⁻¹ r                       (3 axes)
//   ([p − p_s]× + H B⁻¹ J_vᵀ) F = (n_m − ñ_g) + H B⁻¹ r    (F/T: 3 more)
// zero as soon as the force is. A 3-axis sensor solves the first; an F/T sensor both, by least
// squares weighted with the sensor's noise: near a centre of percussion, where the base force
// does not feel the push at first, its moment still does. NaN when the system is
// ill-conditioned or B is not factored. Route (a) differentiates q̇: F̂ itself follows the force,
// through its filter.
ContactEstimator::ReleaseForces ContactEstimator::sensor_release_forces(
    const BaseWrench& base) noexcept {
  constexpr double kMinConditionInverse = 1e-3;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (differentiation_) return {base.force_W.norm(), base.force_W.norm()};
  if (!out_.status.ok() || !base.force_W.allFinite()) return {};
  const Pose& X_WL = data_.X_WB[static_cast<std::size_t>(release_link_)];
  const Vector3 p_W = X_WL.act(release_point_L_);
  point_jacobian(model_, data_, release_link_, p_W, J_);
  const bool moments = base.dn_W.allFinite();
  const Vector3& p_s = options_.sensor.X_WS.translation;
  // G, H: (f̃_g, ñ_g) = −(f_0, n_0 − p_s × f_0), f_0 affine in q̈ (stage 4): column j of
  // ∂f_0/∂q̈ is (m s_v − h × s_ω, h × s_v + I_O s_ω) of the subtree of joint j.
  for (int j = 1; j < model_.num_bodies(); ++j) {
    const auto js = static_cast<std::size_t>(j);
    const Vector6& sj = data_.S[js];
    const Vector3& h = data_.composite_first_moment[js];
    dforce_dddq_.col(j - 1) = h.cross(sj.tail<3>()) - data_.composite_mass[js] * sj.head<3>();
    if (moments) {
      dmoment_dddq_.col(j - 1) =
          -(h.cross(sj.head<3>()) + data_.composite_inertia_O[js] * sj.tail<3>()) -
          p_s.cross(dforce_dddq_.col(j - 1));
    }
  }
  minv_jvt_r_.leftCols<3>() = J_.topRows<3>().transpose();
  minv_jvt_r_.col(3) = observer_.residual();
  if (n_ <= kInlineJoints) {
    ldlt_solve_columns(mass_ldlt_, minv_jvt_r_);
  } else {
    data_.mass_llt.solveInPlace(minv_jvt_r_);
  }
  const auto minv_jvt = minv_jvt_r_.leftCols<3>();  // B⁻¹ J_vᵀ
  const auto minv_r = minv_jvt_r_.col(3);           // B⁻¹ r
  Matrix3 A = Matrix3::Identity() + dforce_dddq_ * minv_jvt;
  Vector3 y = base.force_W + dforce_dddq_ * minv_r;
  if (moments) {
    // Rows weighted by 1/σ: the force rows by 1/σ_f, the moment rows by 1/σ_n (the noise model
    // when configured, else σ_n = σ_f × 0.1 m).
    double lever = 0.1;  // σ_n/σ_f [m]
    if (noise_.configured && noise_.force_W.trace() > 0.0 && noise_.moment_W.trace() > 0.0)
      lever = std::sqrt(noise_.moment_W.trace() / noise_.force_W.trace());
    const Matrix3 A_n = (skew(p_W - p_s) + dmoment_dddq_ * minv_jvt) / lever;
    const Vector3 y_n = (base.dn_W + dmoment_dddq_ * minv_r) / lever;
    y = A.transpose() * y + A_n.transpose() * y_n;  // normal equations
    A = A.transpose() * A + A_n.transpose() * A_n;
  }
  // 3×3 by cofactors; 1/κ_F = 1/(‖A‖_F ‖A⁻¹‖_F) ≤ σ_min/σ_max judges the conditioning (of the
  // normal matrix: its square).
  const double det = A.determinant();
  const Matrix3 A_inv = A.inverse();
  const double min_inverse =
      moments ? kMinConditionInverse * kMinConditionInverse : kMinConditionInverse;
  const double predicted =
      std::isfinite(det) && det != 0.0 && 1.0 / (A.norm() * A_inv.norm()) > min_inverse
          ? (A_inv * y).norm()
          : kInf;
  // The force with q̈ measured instead (q̇ differentiated, low-passed at differentiation_cutoff):
  // F̂(q̈̃) = F̂ − G (q̈̃ − q̈̂). It lags by the filter but does not depend on how well the base
  // feels the push through q̈_free, nor on the isolated link and point. Either below the release
  // level for min_duration releases: while the push lasts both see it. The measured one below it
  // releases after sensor_release_duration: the predicted one alone can dip with a model error
  // amplified by an ill-conditioned system or a wrong point (a collision's first milliseconds).
  double measured = kInf;
  if (ddq_.allFinite() && ddq_filtered_.allFinite()) {
    b_ = ddq_filtered_ - ddq_;
    measured = (base.force_W - dforce_dddq_ * b_).norm();
  }
  const double either = std::min(predicted, measured);
  ReleaseForces out;
  if (std::isfinite(either)) out.either = either;
  if (std::isfinite(measured)) out.measured = measured;
  return out;
}

}  // namespace extwrench
