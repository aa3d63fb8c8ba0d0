#include "extwrench/estimation/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace extwrench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMaxRelativeForceSigma = 0.9;

/// (J Jᵀ + μ² I)⁻¹ over the first `cols` columns of J (R×n), by the LDLᵀ of the solve
/// (damped_least_squares.hpp). False when it is not positive definite.
template <int R, typename Derived>
bool damped_normal_inverse(const Eigen::MatrixBase<Derived>& J, int cols, double damping,
                           Eigen::Matrix<double, R, R>& inverse) noexcept {
  Eigen::Matrix<double, R, R> L;
  L.noalias() = J.leftCols(cols) * J.leftCols(cols).transpose();
  L.diagonal().array() += damping;
  if (!ldlt_in_place(L)) return false;
  inverse.setIdentity();
  for (int k = 0; k < R; ++k) {
    auto column = inverse.col(k);
    ldlt_solve(L, column);
  }
  return true;
}

/// The (damped) pseudo-inverse of J Jᵀ (J: the first `cols` columns, R×n) on the observable
/// subspace: Σ_k v_k v_kᵀ / (v_kᵀ J Jᵀ v_k + μ²) over the first `rank` columns v_k of `basis`, the
/// eigenvectors min_norm_solve kept, μ² its damping. P J τ̂ is its solution, so P stands for A⁻¹
/// in a partial fit.
template <int R, typename Derived, typename Basis>
Eigen::Matrix<double, R, R> observable_inverse(const Eigen::MatrixBase<Derived>& J, int cols,
                                               const Eigen::MatrixBase<Basis>& basis, int rank,
                                               double damping) noexcept {
  Eigen::Matrix<double, R, R> normal;
  normal.noalias() = J.leftCols(cols) * J.leftCols(cols).transpose();
  Eigen::Matrix<double, R, R> inverse = Eigen::Matrix<double, R, R>::Zero();
  for (int k = 0; k < rank; ++k) {
    const Eigen::Matrix<double, R, 1> v = basis.col(k);
    const double lambda = v.dot(normal * v);
    if (lambda > 0.0) inverse.noalias() += (v / (lambda + damping)) * v.transpose();
  }
  return inverse;
}

/// Σ_i σ_i² a_i a_iᵀ over the first `cols` columns of A (R×n): A Σ_τ Aᵀ without an R×n temporary.
template <int R, typename Derived>
Eigen::Matrix<double, R, R> weighted_gram(const Eigen::MatrixBase<Derived>& A, int cols,
                                          const VectorX& variance) noexcept {
  Eigen::Matrix<double, R, R> K = Eigen::Matrix<double, R, R>::Zero();
  for (int i = 0; i < cols; ++i) K.noalias() += variance[i] * A.col(i) * A.col(i).transpose();
  return K;
}

/// The second moment of damping's bias −μ² A⁻¹ x, x of norm s in no preferred direction:
/// s² μ⁴ A⁻². Along an eigenvector of J Jᵀ with eigenvalue λ its 1-σ is s μ²/(λ + μ²): the share of
/// x damping removes there (0 undamped, → 1 at the singularity).
template <int R>
Eigen::Matrix<double, R, R> damping_bias(const Eigen::Matrix<double, R, R>& inverse, double damping,
                                         double scale) noexcept {
  const double k = scale * damping;
  return (k * k) * inverse * inverse;
}

// D (26): the unknowns are M̄; F̂ comes from the sensor.
Matrix6 force_sensor_case(const Matrix6X& J, int link, const WrenchFit& fit,
                          const NoiseModel& noise) noexcept {
  Matrix6 out;
  Matrix3 inverse;
  if (fit.partial) {
    inverse = observable_inverse<3>(J.bottomRows<3>(), link, fit.basis_W.block<3, 3>(3, 3),
                                    fit.rank - 3, fit.damping);
  } else if (!damped_normal_inverse<3>(J.bottomRows<3>(), link, fit.damping, inverse)) {
    out.setConstant(kNaN);
    return out;
  }
  Matrix3 coupling;  // C = J_ω J_vᵀ: how the sensor force enters τ̂ − J_vᵀ F̂
  coupling.noalias() = J.bottomRows<3>().leftCols(link) * J.topRows<3>().leftCols(link).transpose();
  const Matrix3 gain = inverse * coupling;  // ∂M̄/∂F̂ = −A⁻¹ C
  const Matrix3 torque_part = weighted_gram<3>(J.bottomRows<3>(), link, noise.residual_variance);
  out.topLeftCorner<3, 3>() = noise.force_W;
  out.bottomLeftCorner<3, 3>().noalias() = -gain * noise.force_W;
  out.topRightCorner<3, 3>() = out.bottomLeftCorner<3, 3>().transpose();
  out.bottomRightCorner<3, 3>().noalias() = inverse * torque_part * inverse;
  out.bottomRightCorner<3, 3>().noalias() += gain * noise.force_W * gain.transpose();
  if (fit.damping > 0.0)
    out.bottomRightCorner<3, 3>() += damping_bias<3>(inverse, fit.damping, fit.moment_O.norm());
  return out;
}

// E (27): the unknowns are (F̂, M̄), all from the residual.
Matrix6 no_sensor_case(const Matrix6X& J, int link, const WrenchFit& fit,
                       const NoiseModel& noise) noexcept {
  Matrix6 inverse;
  if (fit.partial) {
    inverse = observable_inverse<6>(J, link, fit.basis_W, fit.rank, fit.damping);
  } else if (!damped_normal_inverse<6>(J, link, fit.damping, inverse)) {
    return Matrix6::Constant(kNaN);
  }
  Vector6 x;
  x << fit.force_W, fit.moment_O;
  Matrix6 out;
  out.noalias() = inverse * weighted_gram<6>(J, link, noise.residual_variance) * inverse;
  if (fit.damping > 0.0) out += damping_bias<6>(inverse, fit.damping, x.norm());
  return out;
}

// C (17): (F̂, M̄) = T (F̂, n_m − ñ_g), T = [I 0; −[r_{s,l}]× I].
Matrix6 force_torque_case(const NoiseModel& noise, const Vector3& r_sl) noexcept {
  const Matrix3 shift = -skew(r_sl);  // ∂M̄/∂F̂
  Matrix6 out;
  out.topLeftCorner<3, 3>() = noise.force_W;
  out.bottomLeftCorner<3, 3>().noalias() = shift * noise.force_W;
  out.topRightCorner<3, 3>() = out.bottomLeftCorner<3, 3>().transpose();
  out.bottomRightCorner<3, 3>() = noise.moment_W;
  out.bottomRightCorner<3, 3>().noalias() += shift * noise.force_W * shift.transpose();
  return out;
}

Matrix3 rotated_diagonal(const Matrix3& R, const Vector3& sigma) {
  return R * sigma.cwiseAbs2().asDiagonal() * R.transpose();
}

}  // namespace

NoiseModel make_noise_model(const UncertaintyOptions& options, int n, const Matrix3& R_WS) {
  NoiseModel m;
  const VectorX& s = options.residual_sigma;
  m.residual_variance = s.size() == 1 ? VectorX::Constant(n, s[0] * s[0]) : VectorX(s.cwiseAbs2());
  m.force_W = rotated_diagonal(R_WS, options.sensor_force_sigma);
  m.moment_W = rotated_diagonal(R_WS, options.sensor_moment_sigma);
  m.configured = (m.residual_variance.array() > 0.0).any() ||
                 (options.sensor_force_sigma.array() > 0.0).any() ||
                 (options.sensor_moment_sigma.array() > 0.0).any();
  return m;
}

Matrix6 wrench_covariance(SensorType type, const Matrix6X& J, int link, const WrenchFit& fit,
                          const NoiseModel& noise, const Vector3& r_sl) noexcept {
  switch (type) {
    case SensorType::kForceTorque:
      return force_torque_case(noise, r_sl);
    case SensorType::kForce:
      return force_sensor_case(J, link, fit, noise);
    case SensorType::kNone:
      break;
  }
  return no_sensor_case(J, link, fit, noise);
}

Matrix3 known_point_force_covariance(const Matrix6X& J_p, int link, const WrenchFit& fit,
                                     const NoiseModel& noise) noexcept {
  const auto J_v = J_p.topRows<3>();
  const Matrix3 inverse =
      observable_inverse<3>(J_v, link, fit.basis_W.topLeftCorner<3, 3>(), fit.rank, fit.damping);
  Matrix3 out = inverse * weighted_gram<3>(J_v, link, noise.residual_variance) * inverse;
  if (fit.damping > 0.0) out += damping_bias<3>(inverse, fit.damping, fit.force_W.norm());
  return out;
}

double point_force_misfit(const Matrix6X& J_p, int link, const VectorX& tau_ext,
                          const WrenchFit& fit, const NoiseModel& noise) noexcept {
  const int dof = link - fit.rank;
  if (dof <= 0) return 1.0;
  double chi2 = 0.0;
  for (int i = 0; i < link; ++i) {
    const double variance = noise.residual_variance[i];
    if (!(variance > 0.0)) return 1.0;  // a joint without a noise level: no scale to judge by
    const double misfit = tau_ext[i] - J_p.col(i).head<3>().dot(fit.force_W);
    chi2 += misfit * misfit / variance;
  }
  const double bound = dof + 4.0 * std::sqrt(2.0 * dof);
  return chi2 > bound ? chi2 / dof : 1.0;
}

Matrix3 moment_at_point_covariance(const Matrix6& wrench, const Vector3& r_lp) noexcept {
  Eigen::Matrix<double, 3, 6> T;  // M = M̄ − r_{l,p} × F
  T << skew(r_lp).transpose(), Matrix3::Identity();
  return T * wrench * T.transpose();
}

Matrix3 line_covariance(const Vector3& force, const Vector3& moment_O, const Matrix6& wrench,
                        double lambda) noexcept {
  const double f2 = force.squaredNorm();
  const double f = std::sqrt(f2);
  const Vector3 u = force / f;
  const Matrix3 across = Matrix3::Identity() - u * u.transpose();  // only the offset ⟂ u counts
  Eigen::Matrix<double, 3, 6> jac;                                 // ∂p/∂(F, M̄)
  jac.leftCols<3>() = -skew(moment_O) / f2 -
                      (2.0 / (f2 * f2)) * force.cross(moment_O) * force.transpose() +
                      (lambda / f) * across;
  jac.rightCols<3>() = skew(force) / f2;
  const Eigen::Matrix<double, 3, 6> offset = across * jac;
  // (20) divides by ‖F‖ and ‖F‖²: when ‖F̂‖ is itself uncertain (ρ = σ_F/‖F̂‖), the true line
  // can lie further than the first order says. The 1/‖F‖ of the Jacobian is taken at the
  // smallest force within 1σ, ‖F̂‖(1 − ρ) (ρ capped at kMaxRelativeForceSigma, beyond which the line
  // means little anyway and `uncertain` is set).
  const double rho = std::min(std::sqrt(std::max(wrench.topLeftCorner<3, 3>().trace(), 0.0)) / f,
                              kMaxRelativeForceSigma);
  const double inflation = 1.0 / ((1.0 - rho) * (1.0 - rho));
  return inflation * (offset * wrench * offset.transpose());
}

Matrix3 surface_point_covariance(const Matrix3& line, const Vector3& direction,
                                 const Vector3& normal) noexcept {
  const Matrix3 slide =
      Matrix3::Identity() - direction * normal.transpose() / normal.dot(direction);
  return slide * line * slide.transpose();
}

double rms_sigma(const Matrix3& covariance) noexcept {
  return std::sqrt(std::max(covariance.trace(), 0.0));
}

bool force_uncertain(double sigma_force, double force_norm,
                     const UncertaintyOptions& options) noexcept {
  const double bound = options.uncertain_sigmas * sigma_force;
  return bound > options.uncertain_fraction * (force_norm - bound);
}

}  // namespace extwrench
