// Release from the base sensor (docs/estimator.md#release-from-the-sensor): stage 5b of
// ContactEstimator::update, apart from the stages so that detection and isolation stay short.
#include <Eigen/LU>
#include <cmath>

#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/contact_estimator.hpp"

namespace extwrench {

// 5b. With a base sensor, while a contact on link l (point p of the last sample) is declared:
// the external force the sensor gives at this instant without the residual's lag
// (docs/estimator.md#release-from-the-sensor). Route (b) predicts the base force with
// q̈̂ = q̈_free + B⁻¹ r, q̈_free = B⁻¹ (τ − τ_f − c), so F̂ decays with r after the push ends; with
// the true q̈ = q̈_free + B⁻¹ J_vᵀ F and G = ∂f̃_g/∂q̈, F̂(q̈) = F gives
//   (I + G B⁻¹ J_vᵀ) F = F̂ + G B⁻¹ r,
// zero as soon as the force is. NaN when that 3×3 system is ill-conditioned (a push near the
// centre of percussion of the arm, which the base does not feel at first) or B is not factored.
// Route (a) differentiates q̇: F̂ itself follows the force, through its filter.
double ContactEstimator::sensor_release_force(const BaseWrench& base) noexcept {
  constexpr double kMinConditionInverse = 1e-3;
  if (differentiation_) return base.force_W.norm();
  if (!out_.status.ok() || !base.force_W.allFinite()) return ContactDetector::kNoReleaseForce;
  const Pose& X_WL = data_.X_WB[static_cast<std::size_t>(release_link_)];
  point_jacobian(model_, data_, release_link_, X_WL.act(release_point_L_), J_);
  // G: f̃_g = −f_0 and f_0 is affine in q̈ (stage 4): column j = −(m s_v − h × s_ω) of joint j.
  for (int j = 1; j < model_.num_bodies(); ++j) {
    const auto js = static_cast<std::size_t>(j);
    const Vector6& sj = data_.S[js];
    const Vector3& h = data_.composite_first_moment[js];
    dforce_dddq_.col(j - 1) = h.cross(sj.tail<3>()) - data_.composite_mass[js] * sj.head<3>();
  }
  minv_jvt_ = J_.topRows<3>().transpose();
  b_ = observer_.residual();
  if (n_ <= kInlineJoints) {
    for (int k = 0; k < 3; ++k) {
      auto col = minv_jvt_.col(k);
      ldlt_solve(mass_ldlt_, col);
    }
    ldlt_solve(mass_ldlt_, b_);
  } else {
    data_.mass_llt.solveInPlace(minv_jvt_);
    data_.mass_llt.solveInPlace(b_);
  }
  const Matrix3 A = Matrix3::Identity() + dforce_dddq_ * minv_jvt_;
  // 3×3 by cofactors; 1/κ_F = 1/(‖A‖_F ‖A⁻¹‖_F) ≤ σ_min/σ_max judges the conditioning.
  const double det = A.determinant();
  if (!std::isfinite(det) || det == 0.0) return ContactDetector::kNoReleaseForce;
  const Matrix3 A_inv = A.inverse();
  if (!(1.0 / (A.norm() * A_inv.norm()) > kMinConditionInverse))
    return ContactDetector::kNoReleaseForce;
  return (A_inv * (base.force_W + dforce_dddq_ * b_)).norm();
}

}  // namespace extwrench
