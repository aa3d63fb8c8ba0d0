// Release from the base sensor (docs/estimator.md#release-from-the-sensor): stage 5b of
// ContactEstimator::update, apart from the stages so that detection and isolation stay short.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/contact_estimator.hpp"

namespace extwrench {
namespace {

// ldlt_solve_columns for N joints in fixed-size copies (unrolled; the same operations and bits).
template <int N, typename Factor, typename Columns>
void solve_columns_fixed(const Factor& factor, Columns& X) noexcept {
  const Eigen::Matrix<double, N, N> A = factor;
  Eigen::Matrix<double, N, 4, Eigen::RowMajor> Y = X;
  ldlt_solve_columns(A, Y);
  X = Y;
}

}  // namespace

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
  // With q̈̂ differentiated (route (a)) or given by the caller, F̂ has no residual lag.
  if (differentiation_ || ddq_supplied_) return {base.force_W.norm(), base.force_W.norm()};
  if (!out_.status.ok() || !root_wrench_dddq_valid_ || !base.force_W.allFinite()) return {};
  const Pose& X_WL = data_.X_WB[static_cast<std::size_t>(release_link_)];
  const Vector3 p_W = X_WL.act(release_point_L_);
  const bool moments = base.dn_W.allFinite();
  const Vector3& p_s = options_.sensor.X_WS.translation;
  // B⁻¹ [J_vᵀ r], J_v of p (J_ is scratch until stage 8).
  point_jacobian(model_, data_, release_link_, p_W, J_);
  minv_jvt_r_.leftCols<3>() = J_.topRows<3>().transpose();
  minv_jvt_r_.col(3) = observer_.residual();
  if (n_ == 7) {
    solve_columns_fixed<7>(mass_ldlt_, minv_jvt_r_);
  } else if (n_ == 6) {
    solve_columns_fixed<6>(mass_ldlt_, minv_jvt_r_);
  } else if (n_ <= kInlineJoints) {
    ldlt_solve_columns(mass_ldlt_, minv_jvt_r_);
  } else {
    data_.mass_llt.solveInPlace(minv_jvt_r_);
  }
  // One pass over the joints: A = I + G B⁻¹ J_vᵀ, y = F̂ + G B⁻¹ r and (F/T) their moment rows,
  // with G = ∂f̃_g/∂q̈ = −∂f_0/∂q̈ and H = ∂ñ_g/∂q̈ = −(∂n_0/∂q̈ − p_s × ∂f_0/∂q̈) (stage 4's
  // columns: (f̃_g, ñ_g) = −(f_0, n_0 − p_s × f_0)); G (q̈̃ − q̈̂) for the measured force.
  const bool measured_ok = ddq_.allFinite() && ddq_filtered_.allFinite();
  Matrix3 A = Matrix3::Identity();
  Vector3 y = base.force_W;
  Matrix3 A_n = skew(p_W - p_s);
  Vector3 y_n = base.dn_W;
  Vector3 g_dddq = Vector3::Zero();  // G (q̈̃ − q̈̂)
  for (int j = 0; j < n_; ++j) {
    const auto d = root_wrench_dddq_.col(j);
    const Vector3 g = -d.head<3>();
    const auto row = minv_jvt_r_.row(j);
    A.noalias() += g * row.head<3>();
    y += row[3] * g;
    if (moments) {
      const Vector3 h = p_s.cross(d.head<3>()) - d.tail<3>();
      A_n.noalias() += h * row.head<3>();
      y_n += row[3] * h;
    }
    if (measured_ok) g_dddq += (ddq_filtered_[j] - ddq_[j]) * g;
  }
  if (moments) {
    // Rows weighted by 1/σ: the force rows by 1/σ_f, the moment rows by 1/σ_n (the noise model
    // when configured, else σ_n = σ_f × 0.1 m).
    double lever = 0.1;  // σ_n/σ_f [m]
    if (noise_.configured && noise_.force_W.trace() > 0.0 && noise_.moment_W.trace() > 0.0)
      lever = std::sqrt(noise_.moment_W.trace() / noise_.force_W.trace());
    A_n /= lever;
    y_n /= lever;
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
  const double measured = measured_ok ? (base.force_W - g_dddq).norm() : kInf;
  const double either = std::min(predicted, measured);
  ReleaseForces out;
  if (std::isfinite(either)) out.either = either;
  if (std::isfinite(measured)) out.measured = measured;
  return out;
}

}  // namespace extwrench
