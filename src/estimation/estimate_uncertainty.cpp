// Stage 10 of ContactEstimator::update: the uncertainty of every estimate of the sample
// (docs/estimator.md#uncertainty), apart from the stages so that they stay short. The formulas
// are in uncertainty.hpp.
#include <cmath>

#include "extwrench/estimation/contact_estimator.hpp"

namespace extwrench {

// A force from the base sensor alone (no contact link, or its Table I case not solved): Σ_F is
// the sensor's.
void ContactEstimator::sensor_force_uncertainty() noexcept {
  out_.force_covariance_W = noise_.force_W;
  out_.sigma_force = rms_sigma(noise_.force_W);
}

// The observable part of a rank-deficient case (partial): Σ of the minimum-norm solution, zero
// across the unobservable directions (the estimate says nothing there: observable_basis_W).
void ContactEstimator::partial_uncertainty(int link, const WrenchFit& fit,
                                           std::uint32_t& flags) noexcept {
  if (fit.point_force) {  // known_point_force: J_ holds the point's Jacobian
    out_.force_covariance_W = known_point_force_covariance(J_, link, fit, noise_);
    // The force alone assumes no moment at the point. With more joints than observable
    // directions the residual can refute it: a misfit beyond its noise (a pure moment, a
    // different point) makes the estimate uncertain and Σ_F grows by the misfit's excess.
    const double excess = point_force_misfit(J_, link, tau_ext_, fit, noise_);
    if (excess > 1.0) {
      out_.force_covariance_W *= excess;
      flags |= EstimateFlag::kUncertain;
    }
    out_.sigma_force = rms_sigma(out_.force_covariance_W);
    return;
  }
  const Vector3& O_l = data_.X_WB[static_cast<std::size_t>(link)].translation;
  const Matrix6 wrench = wrench_covariance(options_.sensor.type, J_, link, fit, noise_,
                                           O_l - options_.sensor.X_WS.translation);
  out_.force_covariance_W = wrench.topLeftCorner<3, 3>();
  out_.sigma_force = rms_sigma(out_.force_covariance_W);
  if ((flags & EstimateFlag::kMoment) != 0) {
    // Case D's observable part at the known point: M = M̄ − B Bᵀ (r_{l,p} × F) (stage 9).
    const auto B = fit.basis_W.block<3, 3>(3, 3);
    Eigen::Matrix<double, 3, 6> T;
    T << -(B * B.transpose()) * skew(out_.point_W - O_l), Matrix3::Identity();
    out_.moment_covariance_W = T * wrench * T.transpose();
    out_.sigma_moment = rms_sigma(out_.moment_covariance_W);
  }
}

// 10. In: the link, the fit of stage 8, J_ = J_l of O_l, out_ of stages 8–9 and the surface
// normal of stage 9. Out: out_'s covariances and 1-σ; kUncertain in `flags` when, in contact,
// the force's error bound is too large a share of it.
void ContactEstimator::uncertainty(int link, const WrenchFit& fit, std::uint32_t& flags) noexcept {
  const SensorType type = options_.sensor.type;
  if (fit.partial) {
    partial_uncertainty(link, fit, flags);
  } else if (!fit.ok) {
    if (type != SensorType::kNone && (flags & EstimateFlag::kForce) != 0 && !fit.fitted_force)
      sensor_force_uncertainty();
  } else {
    const Vector3& O_l = data_.X_WB[static_cast<std::size_t>(link)].translation;
    const Matrix6 wrench =
        wrench_covariance(type, J_, link, fit, noise_, O_l - options_.sensor.X_WS.translation);
    out_.force_covariance_W = wrench.topLeftCorner<3, 3>();
    out_.sigma_force = rms_sigma(out_.force_covariance_W);
    if ((flags & EstimateFlag::kMoment) != 0) {
      out_.moment_covariance_W = moment_at_point_covariance(wrench, out_.point_W - O_l);
      out_.sigma_moment = rms_sigma(out_.moment_covariance_W);
    }
    if ((flags & EstimateFlag::kLineOfAction) != 0) {
      // At the reported point's abscissa: the line's offset there is what the point inherits.
      const double lambda = out_.point_W.allFinite()
                                ? out_.line_direction_W.dot(out_.point_W - out_.line_point_W)
                                : 0.0;
      const Matrix3 line = line_covariance(fit.force_W, fit.moment_O, wrench, lambda);
      out_.sigma_line = rms_sigma(line);
      if ((flags & EstimateFlag::kSurfacePoint) != 0) {
        out_.sigma_point =
            rms_sigma(surface_point_covariance(line, out_.line_direction_W, surface_normal_W_));
      } else if ((flags & EstimateFlag::kSurfaceMissed) != 0) {
        out_.sigma_point = out_.sigma_line;  // the nearest point follows the line's offset
      }
    }
  }
  // Judged for a declared contact only: a free sample's force is ~0, its relative error moot.
  if (out_.contact && std::isfinite(out_.sigma_force) &&
      force_uncertain(out_.sigma_force, out_.force_W.norm(), options_.uncertainty))
    flags |= EstimateFlag::kUncertain;
}

}  // namespace extwrench
