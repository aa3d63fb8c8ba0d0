#include "model_check.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace extwrench::calibration_detail {
namespace {

// A pattern is named when its regression explains at least this share of the variance.
constexpr double kJointShare = 0.3;
constexpr double kPoseShare = 0.5;
// A base-force offset is named when its mean exceeds this many standard deviations of the rest.
constexpr double kOffsetSpreads = 2.0;
// High-frequency residual: named when the residual filter at kSuggestedCutoff would leave at most
// this share of the calibrated residual's variance (its spread would drop to ~55 %). White torque
// noise, which the observer's own first-order law filters, leaves 45 % at K = 100 and more at
// lower gains: a smaller share is noise that enters after that filter, through K B(q) δq̇.
constexpr double kSuggestedCutoff = 1.0 / kFastWindow;  // [Hz]
constexpr double kHighFrequencyLeft = 0.3;
// Friction that lags the reversals: named when the Dahl sign lowers the friction fit's residual
// sum of squares by this share (the real Panda's wrist: 29-44 %; a tanh friction's: none).
constexpr double kMinDahlGain = 0.2;
// The velocity's noise through the observer's momentum: the residual's and the regressor's parts
// above ~1/kFastWindow (a centred mean over kFastWindow removed) fitted with R² ≥ kNoiseFit and
// a slope in [kNoiseSlopeMin, kNoiseSlopeMax] around the 1 that a velocity error the torque does
// not see gives (the real Panda at K = 50: 0.96-0.97, R² 0.95-0.99 on joints 1-4).
constexpr double kNoiseFit = 0.5;
constexpr double kNoiseSlopeMin = 0.5;
constexpr double kNoiseSlopeMax = 1.5;

/// y ≈ c + a x1 + b x2 by least squares over the used samples: b, and the share of y's variance
/// that x2 explains beyond x1 (R² of both minus R² of x1 alone).
struct SecondRegressor {
  double slope = 0.0, extra_r2 = 0.0;
};
SecondRegressor fit_beyond(const std::vector<double>& y, const std::vector<double>& x1,
                           const std::vector<double>& x2, const std::vector<char>& use) {
  double n = 0, m1 = 0, m2 = 0, my = 0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    if (!use[k]) continue;
    n += 1;
    m1 += x1[k];
    m2 += x2[k];
    my += y[k];
  }
  SecondRegressor out;
  if (n < 4) return out;
  m1 /= n;
  m2 /= n;
  my /= n;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  double yy = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    if (!use[k]) continue;
    const Eigen::Vector2d x(x1[k] - m1, x2[k] - m2);
    A += x * x.transpose();
    b += x * (y[k] - my);
    yy += (y[k] - my) * (y[k] - my);
  }
  if (yy <= 1e-300 || A(1, 1) <= 1e-300) return out;
  const double r2_first = A(0, 0) > 1e-300 ? b[0] * b[0] / (A(0, 0) * yy) : 0.0;
  const Eigen::Vector2d coef =
      (A + 1e-12 * A.trace() * Eigen::Matrix2d::Identity()).ldlt().solve(b);
  out.slope = coef[1];
  out.extra_r2 = std::max(coef.dot(b) / yy - r2_first, 0.0);
  return out;
}

/// Variance of x over the used samples.
double variance(const std::vector<double>& x, const std::vector<char>& use) {
  double n = 0.0, sum = 0.0, sum2 = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!use[k]) continue;
    n += 1;
    sum += x[k];
    sum2 += x[k] * x[k];
  }
  return n < 2 ? 0.0 : sum2 / n - (sum / n) * (sum / n);
}

/// RMS of the part of a series of this variance that a fit with this R² explains.
double explained_rms(double r2, double variance) { return std::sqrt(std::max(r2, 0.0) * variance); }

std::string num(double x) { return number_text(x, 3); }

// "the robot's inertia along it is |δI| kg m^2 larger|smaller than the model's (why)".
std::string inertia_size_and_sign(double delta) {
  return "the robot's inertia along it is " + num(std::abs(delta)) + " kg m^2 " +
         (delta > 0 ? "larger" : "smaller") + " than the model's (" +
         (delta > 0 ? "a rotor inertia the model lacks"
                    : "the model's link inertias are too large, or the torque lags the velocity") +
         ")";
}

// What lowers the velocity's noise on a joint with these filters [Hz] (0: none).
std::string velocity_noise_remedy(double residual_cutoff, double velocity_cutoff) {
  if (residual_cutoff > 0.0 || velocity_cutoff > 0.0) {
    std::string filters;
    if (velocity_cutoff > 0.0) filters = "velocity filter's " + num(velocity_cutoff) + " Hz";
    if (residual_cutoff > 0.0)
      filters += (filters.empty() ? "" : ", ") + std::string("residual filter's ") +
                 num(residual_cutoff) + " Hz";
    const bool both = residual_cutoff > 0.0 && velocity_cutoff > 0.0;
    return "a lower cutoff than this joint's " + filters + (both ? "" : ", the other filter,") +
           " or a lower gain lowers it further, at the cost of delay";
  }
  return "observer.velocity_cutoff or observer.residual_cutoff " + num(kSuggestedCutoff) +
         " (Hz) on this joint lowers it (the first keeps the timing of a contact that loads the "
         "torque, the second also removes the torque's noise), and so does a lower gain, at the "
         "cost of delay";
}

}  // namespace

void check_joints(const std::vector<JointSeries>& series, const std::vector<JointSeries>& before,
                  const std::vector<JointFrictionFit>& after, const std::vector<Sample>& samples,
                  const VectorX& residual_cutoff, const VectorX& velocity_cutoff,
                  const std::vector<char>& use, ModelCheck& check) {
  const std::size_t n = series.size();
  const std::vector<double> suggested = residual_filter_weights(samples, kSuggestedCutoff);
  check.joint_rms = VectorX::Zero(static_cast<Eigen::Index>(n));
  std::vector<double> phi, z, z_acc;
  for (std::size_t i = 0; i < n; ++i) {
    const JointSeries& s = series[i];
    const int joint = static_cast<int>(i) + 1;
    double sum2 = 0, count = 0;
    for (std::size_t k = 0; k < s.r0.size(); ++k) {
      if (!use[k]) continue;
      sum2 += before[i].r0[k] * before[i].r0[k];
      count += 1;
    }
    check.joint_rms[static_cast<Eigen::Index>(i)] = count > 0 ? std::sqrt(sum2 / count) : 0.0;
    // Flips with sign(q̇): the model's residual against the observer-filtered sign.
    phi.assign(s.dq.size(), 0.0);
    for (std::size_t k = 0; k < s.dq.size(); ++k)
      phi[k] = s.dq[k] > 0 ? 1.0 : (s.dq[k] < 0 ? -1.0 : 0.0);
    filter_regressor(phi, s.alpha, z, s.filter_weight);
    const LineFit coulomb = fit_line(z, before[i].r0, use);
    if (coulomb.r2 >= kJointShare &&
        explained_rms(coulomb.r2, coulomb.syy / coulomb.count) >= kResolvableTorque) {
      check.patterns.push_back({"coulomb", joint, coulomb.r2,
                                "joint " + std::to_string(joint) +
                                    ": the residual flips with sign(dq) (" +
                                    num(std::abs(coulomb.slope)) + " N m, R^2 " + num(coulomb.r2) +
                                    "): Coulomb friction the model lacks (calibrated)"});
    }
    // Lags the reversals: the same friction with the Dahl sign fits better (fit_joint).
    const DahlAlternative& dahl = after[i].dahl;
    if (dahl.presliding > 0.0 && count > 0 && dahl.rss <= (1.0 - kMinDahlGain) * dahl.sign_rss &&
        std::sqrt((dahl.sign_rss - dahl.rss) / count) >= kResolvableTorque) {
      check.patterns.push_back(
          {"presliding", joint, 1.0 - dahl.rss / dahl.sign_rss,
           "joint " + std::to_string(joint) +
               ": the friction lags the velocity's reversals (a presliding displacement of ~" +
               num(1e3 * dahl.presliding) + " mrad): --sign dahl lowers the friction fit's " +
               "residual RMS from " + num(std::sqrt(dahl.sign_rss / count)) + " to " +
               num(std::sqrt(dahl.rss / count)) + " N m and its largest value from " +
               num(dahl.sign_peak) + " to " + num(dahl.peak) +
               " N m (docs/calibration.md, the Dahl sign)"});
    }
    const double residual_variance = variance(after[i].residual, use);
    // The velocity's noise: a velocity error δq̇ that the torque does not balance enters r as the
    // observer's answer to a momentum error B(q) δq̇ (filter_rate), with slope 1; fast motion that
    // is real is balanced by τ and leaves none. Compared on the fast parts, where the measured
    // velocity is mostly its error and friction or gravity errors have no share.
    const double cutoff = residual_cutoff[static_cast<Eigen::Index>(i)];
    const std::vector<double>& fast_noise = s.momentum_fast;
    const LineFit noise =
        fit_line(fast_noise, fast_part(after[i].residual, samples, kFastWindow), use);
    const double noise_share = noise.count > 0 && residual_variance > 0.0
                                   ? noise.r2 * noise.syy / noise.count / residual_variance
                                   : 0.0;
    const bool noise_fits =
        noise.r2 >= kNoiseFit && noise.slope >= kNoiseSlopeMin && noise.slope <= kNoiseSlopeMax;
    const bool velocity_noise = noise_fits && noise_share >= kJointShare &&
                                explained_rms(noise_share, residual_variance) >= kResolvableTorque;
    // The later fits see the residual without it: central differences of a noisy q̇ follow its
    // noise, and the inertia pattern read it as the joint's inertia (3.9 kg m² on a simulated
    // joint with none missing).
    std::vector<double> without_noise = after[i].residual;
    if (noise_fits)
      for (std::size_t k = 0; k < without_noise.size(); ++k)
        without_noise[k] -= noise.slope * fast_noise[k];
    if (velocity_noise) {
      check.patterns.push_back(
          {"velocity_noise", joint, noise_share,
           "joint " + std::to_string(joint) + ": " + num(100.0 * noise_share) +
               " % of the calibrated residual's variance is the measured velocity's noise, which "
               "the observer passes as K B(q) dq (above ~" +
               num(kSuggestedCutoff) + " Hz the residual follows it with slope " +
               num(noise.slope) + ", R^2 " + num(noise.r2) +
               "): no friction, offset or model parameter removes it; " +
               velocity_noise_remedy(cutoff, velocity_cutoff[static_cast<Eigen::Index>(i)]) +
               "; a cleaner velocity signal removes it too (docs/estimator.md#velocity-filter)"});
    }
    // Follows g(q): the calibrated residual against the filtered gravity torque.
    filter_regressor(s.gravity, s.alpha, z, s.filter_weight);
    const LineFit g = fit_line(z, after[i].residual, use);
    if (g.r2 >= kJointShare && explained_rms(g.r2, residual_variance) >= kResolvableTorque) {
      // Beyond the model's own g_i (a real leg on a force plate: 14.5 times it at the knee) the
      // size alone says more than "a mass error", and a percentage of thousands reads as noise.
      const bool beyond = std::abs(g.slope) > 1.0;
      check.patterns.push_back(
          {"gravity", joint, g.r2,
           "joint " + std::to_string(joint) + ": the calibrated residual follows g(q) (" +
               (beyond ? num(g.slope) + " times the model's own gravity torque on it"
                       : num(100.0 * g.slope) + " % of it") +
               ", R^2 " + num(g.r2) + "): " +
               (beyond ? "a payload heavier than what the joint carries in the model (--payload, "
                         "with a base sensor), or another torque that changes with the "
                         "configuration (a spring, a cable, a contact, a torque sensor's "
                         "angle-dependent offset)"
                       : "a gravity / mass error in the model (a payload? --payload, with a base "
                         "sensor)")});
    }
    // Follows q̈: the calibrated residual against the filtered acceleration (central differences
    // of q̇). r = −δI q̈ when the robot's inertia along the joint exceeds the model's by δI (a
    // rotor inertia the model lacks; B's diagonal, so not a pure g(q) or friction pattern).
    if (after[i].inertia != 0.0) {
      // Fitted with the friction (fit_joint): corrected in the observer's momentum.
      check.patterns.push_back(
          {"inertia", joint, after[i].inertia_gain,
           "joint " + std::to_string(joint) + ": " + inertia_size_and_sign(after[i].inertia) +
               "; corrected by observer.inertia_correction, which removes " +
               num(100.0 * after[i].inertia_gain) + " % of what friction leaves"});
    } else {
      const std::vector<double> acc = central_acceleration(s);
      // Beyond g(q): in a periodic motion the position, hence a gravity error, follows q̈ too.
      filter_regressor(acc, s.alpha, z_acc, s.filter_weight);
      const SecondRegressor inertia = fit_beyond(without_noise, z, z_acc, use);
      if (inertia.extra_r2 >= kJointShare &&
          explained_rms(inertia.extra_r2, variance(without_noise, use)) >= kResolvableTorque) {
        const double delta = -inertia.slope;
        const std::string follows = "joint " + std::to_string(joint) +
                                    ": the calibrated residual follows the joint's acceleration "
                                    "(R^2 " +
                                    num(inertia.extra_r2) + " beyond g(q))";
        // One sine per joint: q̈ follows q, and so does a gravity error that changes with q_i
        // (not a multiple of g_i: a link's centre of mass off). Then both named, and the remedy.
        // Judged on the motion's q̈ (its part below ~20 Hz): a differentiated, quantised encoder's
        // noise in q̈ hid that q̈ follows q (a simulated Panda's joint 2 was then named `inertia`).
        std::vector<double> motion_acc = acc;
        const std::vector<double> fast_acc = fast_part(acc, samples, kFastWindow);
        for (std::size_t k = 0; k < motion_acc.size(); ++k) motion_acc[k] -= fast_acc[k];
        double correlation = 0.0;
        if (inertia_aliases_gravity(s, motion_acc, use, correlation)) {
          check.patterns.push_back(
              {"inertia_or_gravity", joint, inertia.extra_r2,
               follows + ", but in this motion the acceleration follows the position " +
                   "(correlation " + num(correlation) + ", as with one sine per joint): either " +
                   inertia_size_and_sign(delta) +
                   ", or a gravity error that changes with the joint's angle (a centre of mass "
                   "off); record a motion that moves joint " +
                   std::to_string(joint) + " with several frequencies to tell them apart"});
        } else {
          check.patterns.push_back({"inertia", joint, inertia.extra_r2,
                                    follows + ": " + inertia_size_and_sign(delta) +
                                        (delta > 0 ? "; armature: in the configuration" : "")});
        }
      }
    }
    // Mostly above ~20 Hz (unfiltered joints only): the velocity's noise through K B(q), or the
    // torque's, which the residual filter removes (docs/estimator.md#residual-filter).
    if (cutoff > 0.0) continue;
    std::vector<double> low = after[i].residual;
    apply_residual_filter(suggested, low);
    const double total = residual_variance, filtered = variance(low, use);
    if (total > 0.0 && filtered <= kHighFrequencyLeft * total &&
        std::sqrt(total - filtered) >= kResolvableTorque) {
      const double share = 1.0 - filtered / total;
      check.patterns.push_back(
          {"high_frequency", joint, share,
           "joint " + std::to_string(joint) + ": " + num(100.0 * share) +
               " % of the calibrated residual's variance lies above ~" + num(kSuggestedCutoff) +
               " Hz (" +
               (velocity_noise ? "the velocity's noise, named above"
                               : "noise of the torque or the velocity") +
               "): observer.residual_cutoff " + num(kSuggestedCutoff) +
               " (Hz) on this joint lowers its threshold (docs/estimator.md#residual-filter)"});
    }
  }
}

void check_sensor(const std::vector<Vector6>& error_S, const std::vector<Vector6>& predicted_S,
                  bool moments, ModelCheck& check) {
  const auto N = static_cast<double>(error_S.size());
  if (N < 3) return;
  Vector6 mean = Vector6::Zero(), mean_p = Vector6::Zero();
  for (std::size_t k = 0; k < error_S.size(); ++k) {
    mean += error_S[k];
    mean_p += predicted_S[k];
  }
  mean /= N;
  mean_p /= N;
  Vector6 var = Vector6::Zero(), ms = Vector6::Zero();
  for (const Vector6& e : error_S) {
    var += (e - mean).cwiseAbs2();
    ms += e.cwiseAbs2();
  }
  check.sensor_mean = mean;
  check.sensor_rms = (ms / N).cwiseSqrt();
  const Vector3 spread = (var.head<3>() / N).cwiseSqrt();
  const Vector3 offset = mean.head<3>();
  if (offset.norm() > kOffsetSpreads * spread.norm() && offset.norm() > 1e-3) {
    check.patterns.push_back(
        {"base_force_offset", 0, offset.norm() / std::max(spread.norm(), 1e-12),
         "base force: a constant offset of [" + num(offset.x()) + ", " + num(offset.y()) + ", " +
             num(offset.z()) + "] N (" + num(offset.norm() / std::max(spread.norm(), 1e-12)) +
             " x its spread): a sensor bias (calibrated out) or a mass error in the model"});
  }
  if (!moments) return;
  // Sensor moment error linear in the predicted wrench as the configuration changes: a sensor
  // orientation error δθ adds δθ × n̂ to the moment (and a constant δθ × f̂ ≈ −δθ × M g to the
  // force, taken as bias). Least squares of each moment axis on the predicted moment.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < error_S.size(); ++k) {
    const Vector3 p = predicted_S[k].tail<3>() - mean_p.tail<3>();
    const Vector3 e = error_S[k].tail<3>() - mean.tail<3>();
    A += p * p.transpose();
    B += p * e.transpose();
  }
  if (A.trace() <= 1e-300) return;
  const Eigen::Matrix3d coeff =
      (A + 1e-12 * A.trace() * Eigen::Matrix3d::Identity()).ldlt().solve(B);
  double best = 0.0;
  int axis = 0;
  for (int a = 0; a < 3; ++a) {
    const double total = var[3 + a];
    if (total <= 1e-300) continue;
    const double explained = (coeff.col(a).transpose() * A * coeff.col(a))(0, 0);
    const double r2 = explained / total;
    if (r2 > best) {
      best = r2;
      axis = a;
    }
  }
  if (best >= kPoseShare) {
    const char* names[] = {"x", "y", "z"};
    check.patterns.push_back(
        {"sensor_pose", 0, best,
         std::string("base moment: the error about ") + names[axis] +
             " is linear in the predicted moment as the configuration changes (R^2 " + num(best) +
             "): a sensor pose (orientation) error in the configuration"});
  }
}

}  // namespace extwrench::calibration_detail
