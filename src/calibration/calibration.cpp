#include "extwrench/calibration/calibration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/core/time_step.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/observer/residual_filter.hpp"
#include "friction_fit.hpp"
#include "model_check.hpp"
#include "payload_fit.hpp"

namespace extwrench {
namespace {

using calibration_detail::JointFrictionFit;
using calibration_detail::JointSeries;
using calibration_detail::number_text;

// A residual transient is over after this many time constants 1/K (e^{-5} < 1 %).
constexpr double kSettleTimeConstants = 5.0;
constexpr int kParametersPerJoint = 3;  // D, F_c, o
constexpr double kWindowGap = 0.02;     // [s] flagged samples closer than this form one window
constexpr double kReversalLead = 0.1;   // [s] a window this soon after its joint reversed
constexpr double kMadToSigma = 1.4826;  // σ of a Gaussian from its median absolute deviation
// ThresholdModel::kAuto takes a + b|q̇| when its mean over the motion is below this × the
// constant threshold for the same rate.
constexpr double kSpeedGain = 0.95;
// Above this share of the measured torque's RMS left in the calibrated residual: warned.
constexpr double kMaxUnexplainedShare = 0.5;
// No joint threshold below this [N m], in either form: an ideal simulated log's residual is
// rounding, and a threshold fitted to rounding alarms on the next sample's.
constexpr double kMinThreshold = 1e-6;

void check_samples(const std::vector<Sample>& samples, int n, bool known_external_torque) {
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Sample& s = samples[k];
    const std::string where = "sample " + std::to_string(k) + " (t = " + time_text(s.t) + ")";
    if (known_external_torque && !s.has_true_tau_ext) {
      throw Error(where +
                  ": no known external torque (true_tau_ext1..n) for a calibration in contact");
    }
    if (!std::isfinite(s.t)) throw Error(where + ": t is not finite");
    if (k > 0 && !(s.t > samples[k - 1].t)) throw Error(where + ": t does not increase");
    auto check = [&](const VectorX& v, const char* name) {
      if (v.size() != n) {
        throw Error(where + ": " + name + ": expected " + std::to_string(n) + " values, got " +
                    std::to_string(v.size()));
      }
      for (int i = 0; i < n; ++i)
        if (!std::isfinite(v[i]))
          throw Error(where + ": " + name + std::to_string(i + 1) + " is not finite");
    };
    check(s.q, "q");
    check(s.dq, "dq");
    check(s.tau, "tau");
    if (known_external_torque) check(s.truth.tau_ext, "true_tau_ext");
  }
  // The fit integrates the momentum over the time steps: a t in milliseconds or a sample counter
  // (steps a thousand times too long) fits nonsense, which the warnings then blame on contact.
  if (!samples.empty()) {
    const std::string slow =
        slow_time_step(samples.front().t, samples.back().t, static_cast<long>(samples.size()));
    if (!slow.empty()) {
      throw Error(slow +
                  ", and calibration needs the controller's rate (100 Hz to 1 kHz); if t is in "
                  "milliseconds or counts samples, convert it");
    }
  }
}

// With a known external torque: the residual's part due to it, the observer's filter of
// τ_ext,known (the residual answers an external torque as it answers friction, with the
// opposite sign), taken out of r⁰ so that only the model's error is left to fit: from `series`
// (run without friction) and from `before` (with the configured friction), filtered once.
void remove_known_torque(const std::vector<Sample>& samples, int joint, JointSeries& series,
                         JointSeries& before) {
  std::vector<double> tau_ext(samples.size()), filtered;
  for (std::size_t k = 0; k < samples.size(); ++k) tau_ext[k] = samples[k].truth.tau_ext[joint];
  calibration_detail::filter_regressor(tau_ext, series.alpha, filtered);
  for (std::size_t k = 0; k < filtered.size(); ++k) {
    series.r0[k] -= filtered[k];
    before.r0[k] -= filtered[k];
  }
}

// The observer over the log with `friction`: residual r_k per joint (N × n), and e^{−K Δt_k}.
// `momentum_dq`: the q̇ of the momentum per sample (the estimator's velocity filter), friction
// taking the log's; empty: the log's for both.
void run_observer(const Model& model, const VectorX& gains, const JointFriction& friction,
                  const std::vector<Sample>& samples, const std::vector<VectorX>& momentum_dq,
                  std::vector<JointSeries>& series, bool residual_only) {
  const int n = model.nq();
  Data data(model);
  MomentumObserver observer(model, gains);
  observer.set_friction(friction);
  const std::size_t N = samples.size();
  series.assign(static_cast<std::size_t>(n), JointSeries{});
  for (JointSeries& s : series) {
    s.r0.assign(N, 0.0);
    if (!residual_only) {
      s.dq.assign(N, 0.0);
      s.alpha.assign(N, 0.0);
      s.dt.assign(N, 0.0);
    }
  }
  const Sample& first = samples.front();
  if (Status st = observer.reset(model, data, first.t, first.q, first.dq, first.tau); !st.ok())
    throw Error("calibration: observer reset failed at the first sample");
  for (std::size_t k = 0; k < N; ++k) {
    const Sample& s = samples[k];
    if (k > 0 && !observer.validate(s.t, s.q, s.dq, s.tau).ok())
      throw Error("calibration: sample " + std::to_string(k) + " rejected by the observer");
    if (k > 0) {
      const VectorX& dq = momentum_dq.empty() ? s.dq : momentum_dq[k];
      momentum_terms(model, data, s.q, dq);  // as MomentumObserver::update
      observer.integrate(data, s.t, s.q, dq, s.tau, s.dq);
    }
    for (int i = 0; i < n; ++i) {
      JointSeries& js = series[static_cast<std::size_t>(i)];
      js.r0[k] = observer.residual()[i];
      if (residual_only) continue;
      js.dq[k] = s.dq[i];
      js.dt[k] = k > 0 ? s.t - samples[k - 1].t : 0.0;
      js.alpha[k] = k > 0 ? std::exp(-observer.gains()[i] * js.dt[k]) : 0.0;
    }
  }
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Windows where some joint's residual exceeds `sigmas` robust standard deviations for at least
// `min_duration`: the signature of a contact (or of a model far off) rather than of noise.
std::vector<SuspectWindow> suspect_windows(const std::vector<JointFrictionFit>& fits,
                                           const std::vector<Sample>& samples,
                                           const std::vector<char>& use, double sigmas,
                                           double min_duration) {
  const std::size_t n = fits.size(), N = samples.size();
  std::vector<double> centre(n), sigma(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> r;
    for (std::size_t k = 0; k < N; ++k)
      if (use[k]) r.push_back(fits[i].residual[k]);
    centre[i] = median(r);
    for (double& x : r) x = std::abs(x - centre[i]);
    sigma[i] = std::max(kMadToSigma * median(r), 1e-6);
  }
  std::vector<SuspectWindow> out;
  SuspectWindow w;
  bool open = false;
  double excess_best = 0.0;
  auto close = [&] {
    if (open && w.t_end - w.t_begin >= min_duration - 1e-9) out.push_back(w);
    open = false;
  };
  for (std::size_t k = 0; k < N; ++k) {
    if (!use[k]) continue;
    for (std::size_t i = 0; i < n; ++i) {
      const double excess = std::abs(fits[i].residual[k] - centre[i]) / sigma[i];
      if (excess <= sigmas) continue;
      if (open && samples[k].t - w.t_end > kWindowGap) close();
      if (!open) {
        w = SuspectWindow{samples[k].t, samples[k].t, static_cast<int>(i) + 1, 0.0};
        excess_best = 0.0;
        open = true;
      }
      w.t_end = samples[k].t;
      if (excess > excess_best) {
        excess_best = excess;
        w.joint = static_cast<int>(i) + 1;
        w.peak = std::abs(fits[i].residual[k]);
      }
    }
  }
  close();
  return out;
}

// Threshold of one joint for `rate` false alarms per second: Rice's formula for the rate at
// which a Gaussian process of standard deviation σ and mean-crossing rate ν₀ leaves |r| < u,
// 2 ν₀ e^{−u²/2σ²}, solved for u; never below margin × the largest residual seen, scaled from
// the fit window's duration to the target rate as a Gaussian's extreme would be (real residuals
// have heavier tails than the Gaussian fitted to their spread).
void joint_threshold(const std::vector<double>& r, const std::vector<Sample>& samples,
                     const std::vector<char>& use, double rate, double margin, JointFitReport& j) {
  double sum = 0.0, sum2 = 0.0, peak = 0.0, duration = 0.0;
  std::size_t count = 0, peak_at = 0;
  for (std::size_t k = 0; k < r.size(); ++k) {
    if (!use[k]) continue;
    sum += r[k];
    sum2 += r[k] * r[k];
    if (std::abs(r[k]) > peak) {
      peak = std::abs(r[k]);
      peak_at = k;
    }
    ++count;
  }
  const double mean = sum / static_cast<double>(count);
  j.noise_std = std::sqrt(std::max(sum2 / static_cast<double>(count) - mean * mean, 0.0));
  j.rms_after = std::sqrt(sum2 / static_cast<double>(count));
  j.max_after = peak;
  j.max_after_t = samples[peak_at].t;
  std::size_t crossings = 0;
  for (std::size_t k = 1; k < r.size(); ++k) {
    if (!use[k] || !use[k - 1]) continue;
    duration += samples[k].t - samples[k - 1].t;
    if ((r[k - 1] - mean < 0.0) != (r[k] - mean < 0.0)) ++crossings;
  }
  j.crossing_rate = duration > 0 ? 0.5 * static_cast<double>(crossings) / duration : 0.0;
  const double ratio = 2.0 * j.crossing_rate / rate;
  const double target_log = std::log(std::max(ratio, 2.0));
  const double gaussian = j.noise_std * std::sqrt(2.0 * target_log);
  // The largest residual seen is (for a Gaussian) the level crossed about once in the fit
  // window, σ √(2 ln(2 ν₀ T)); scaled as a Gaussian's level grows to the target rate, it keeps
  // the tails the data actually have.
  const double fit_log = std::log(std::max(2.0 * j.crossing_rate * duration, 2.0));
  const double extrapolated = margin * peak * std::sqrt(std::max(target_log / fit_log, 1.0));
  j.threshold_from_max = extrapolated > gaussian;
  j.threshold = std::max(std::max(gaussian, extrapolated), kMinThreshold);
}

// Thresholds that follow the speed: the spread of the residual as a line in |q̇|,
// σ(v) = √(π/2) (e₀ + e₁ v) from the least-squares line through |r_k| against v_k = |q̇_k|
// (E|r| = σ √(2/π) for a zero-mean Gaussian); then the residual normalised by it, z = r / σ(v),
// gets the constant rule (joint_threshold) for the same rate, u, and τ_thr(v) = u σ(v).
// e₀ is kept ≥ a quarter of the mean |r| (else a threshold near zero at rest).
void speed_threshold(const std::vector<double>& r, const std::vector<double>& dq,
                     const std::vector<Sample>& samples, const std::vector<char>& use, double rate,
                     double margin, JointFitReport& j) {
  std::vector<double> speed(r.size()), size(r.size());
  for (std::size_t k = 0; k < r.size(); ++k) {
    speed[k] = std::abs(dq[k]);
    size[k] = std::abs(r[k]);
  }
  const calibration_detail::LineFit line = calibration_detail::fit_line(speed, size, use);
  const double s1 = line.count, mean_e = line.mean_y;
  double e1 = line.slope, e0 = line.intercept;
  if (e1 <= 0.0) {
    e1 = 0.0;
    e0 = mean_e;
  } else if (e0 < 0.25 * mean_e) {
    // Intercept held at e0: the slope through it, Σ v (e − e0) / Σ v², from the centred sums.
    e0 = 0.25 * mean_e;
    const double sv = s1 * line.mean_x, svv = line.sxx + s1 * line.mean_x * line.mean_x;
    const double sve = line.sxy + s1 * line.mean_x * line.mean_y;
    e1 = svv > 0 ? std::max((sve - e0 * sv) / svv, 0.0) : 0.0;
  }
  const double c = std::sqrt(std::acos(-1.0) / 2.0);
  j.noise_at_rest = c * e0;
  j.noise_per_speed = c * e1;
  std::vector<double> z(r.size(), 0.0);
  for (std::size_t k = 0; k < r.size(); ++k)
    z[k] = r[k] / std::max(j.noise_at_rest + j.noise_per_speed * std::abs(dq[k]), 1e-12);
  JointFitReport zj;
  joint_threshold(z, samples, use, rate, margin, zj);
  j.threshold_at_rest = std::max(zj.threshold * j.noise_at_rest, kMinThreshold);
  j.threshold_per_speed = zj.threshold * j.noise_per_speed;
  double sum = 0.0;
  for (std::size_t k = 0; k < r.size(); ++k)
    if (use[k]) sum += j.threshold_at_rest + j.threshold_per_speed * std::abs(dq[k]);
  j.mean_threshold_speed = sum / s1;
}

// Bias of the base sensor: the mean of reading − predicted no-contact reading (sensor frame)
// with the calibrated friction; then F̂_ext's spread per world axis and F_min.
void sensor_calibration(const Model& model, const EstimatorOptions& options,
                        const std::vector<Sample>& samples, const std::vector<char>& use,
                        const CalibrationOptions& o, Calibration& cal) {
  EstimatorOptions opt = apply_calibration(options, cal);
  opt.sensor.tare_samples = 0;
  opt.sensor.bias_S.setZero();
  const Pose& X_WS = opt.sensor.X_WS;
  ContactEstimator est(model, GeometryModel{}, opt);
  Vector6 sum = Vector6::Zero();
  std::size_t count = 0;
  std::vector<Vector6> errors, predictions;  // for the model check
  for (std::size_t pass = 0; pass < 2; ++pass) {
    if (!est.reset(samples.front()).ok()) throw Error("calibration: estimator reset failed");
    Vector3 s1 = Vector3::Zero(), s2 = Vector3::Zero();
    double peak = 0.0, sum_norm = 0.0, last_norm = std::nan("");
    std::vector<double> norms;
    for (std::size_t k = 1; k < samples.size(); ++k) {
      if (!est.update(samples[k]).ok() || !use[k]) continue;
      if (pass == 0) {
        const Vector6 predicted_W = sensor_reading_world(est.data(), X_WS.translation);
        Vector6 predicted_S;
        predicted_S.head<3>() = X_WS.rotation.transpose() * predicted_W.head<3>();
        predicted_S.tail<3>() = X_WS.rotation.transpose() * predicted_W.tail<3>();
        sum += samples[k].reading_S - predicted_S;
        errors.push_back(samples[k].reading_S - predicted_S);
        predictions.push_back(predicted_S);
        ++count;
      } else {
        const Vector3& f = est.result().force_W;
        s1 += f;
        s2 += f.cwiseProduct(f);
        peak = std::max(peak, f.norm());
        norms.push_back(f.norm());
        sum_norm += f.norm();
      }
    }
    if (count == 0) throw Error("calibration: no usable base-sensor sample");
    if (pass == 0) {
      calibration_detail::check_sensor(
          errors, predictions, opt.sensor.type == SensorType::kForceTorque, cal.model_check);
      cal.sensor_bias_S = sum / static_cast<double>(count);
      if (opt.sensor.type == SensorType::kForce) cal.sensor_bias_S.tail<3>().setZero();
      est.set_sensor_bias(cal.sensor_bias_S);
    } else {
      const Vector3 mean = s1 / static_cast<double>(count);
      cal.force_noise_W =
          (s2 / static_cast<double>(count) - mean.cwiseProduct(mean)).cwiseMax(0.0).cwiseSqrt();
      // The same extrapolation of the largest ‖F̂‖ as for the joints (joint_threshold).
      const double mean_norm = sum_norm / static_cast<double>(norms.size());
      std::size_t crossings = 0;
      for (const double x : norms) {
        if (std::isfinite(last_norm) && (last_norm < mean_norm) != (x < mean_norm)) ++crossings;
        last_norm = x;
      }
      const double duration = samples.back().t - samples.front().t;
      const double nu = 0.5 * static_cast<double>(crossings) / duration;
      const double rate = o.false_alarms_per_hour / 3600.0;
      const double target_log = std::log(std::max(2.0 * nu / rate, 2.0));
      const double fit_log = std::log(std::max(2.0 * nu * duration, 2.0));
      cal.force_threshold = std::max(
          o.threshold_margin * peak * std::sqrt(std::max(target_log / fit_log, 1.0)), 1e-3);
    }
  }
}

// A contact over most of the log escapes suspect_windows (its robust spread is the contact's):
// then the calibrated model still explains little of the measured torque. Free motion leaves
// 4-21 % of τ's RMS on the real Panda; the ODRI leg standing on its force plate 80-110 %.
void warn_unexplained_torque(const std::vector<Sample>& samples, const std::vector<char>& use,
                             Calibration& cal) {
  const std::size_t n = cal.joints.size();
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0.0;
    int count = 0;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      if (!use[k]) continue;
      const double tau = samples[k].tau[static_cast<Eigen::Index>(i)];
      sum += tau * tau;
      ++count;
    }
    const double tau_rms = count > 0 ? std::sqrt(sum / count) : 0.0;
    const double share = tau_rms > 0 ? cal.joints[i].rms_after / tau_rms : 0.0;
    if (share <= kMaxUnexplainedShare) continue;
    cal.warnings.push_back(
        "joint " + std::to_string(i + 1) + ": after calibration the residual's RMS is " +
        std::to_string(static_cast<int>(std::lround(100.0 * share))) +
        " % of the measured torque's over [" + time_text(cal.t_begin) + ", " +
        time_text(cal.t_end) +
        "] s: the model explains little of it; a contact during most of the log (the fit "
        "cannot tell it from the robot), or a wrong model. With a known external torque "
        "(a force plate), calibrate in contact (--known-torque)");
  }
}

// (B(q_k) q̇_k)_i along the log, and with the velocity filter its q̇_i (without, the series' dq):
// the model check compares the residual's fast part with what the observer's momentum passes of
// the measured velocity's, and the inertia correction's δI q̇ is added to that q̇.
void momentum_series(const Model& model, const std::vector<Sample>& samples,
                     const std::vector<VectorX>& momentum_dq, std::vector<JointSeries>& series) {
  Data data(model);
  for (JointSeries& js : series) {
    js.momentum.assign(samples.size(), 0.0);
    if (!momentum_dq.empty()) js.momentum_dq.assign(samples.size(), 0.0);
  }
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const VectorX& dq = momentum_dq.empty() ? samples[k].dq : momentum_dq[k];
    const VectorX p = crba(model, data, samples[k].q) * dq;
    for (std::size_t i = 0; i < series.size(); ++i) {
      series[i].momentum[k] = p[static_cast<Eigen::Index>(i)];
      if (!momentum_dq.empty()) series[i].momentum_dq[k] = dq[static_cast<Eigen::Index>(i)];
    }
  }
}

// The observer's answer to the momentum, its part above ~20 Hz, through the residual filter where
// the joint has one (its weights already in the series): the velocity's noise as the detector
// sees it.
void momentum_fast_series(const std::vector<Sample>& samples, std::vector<JointSeries>& series) {
  std::vector<double> z;
  for (JointSeries& js : series) {
    calibration_detail::filter_rate(js.momentum, js.alpha, js.dt, z, js.filter_weight);
    js.momentum_fast = calibration_detail::fast_part(z, samples, calibration_detail::kFastWindow);
  }
}

// g_i(q_k) along the log (the model check's gravity pattern), and the gravity torques of a unit
// mass at the last link's origin and of unit first moments along its axes (a payload's, linear
// in m and m c): with g_i, the nuisance regressors that keep the inertia fit from taking a
// gravity error for an inertia (fit_joint); computed only for it (`payload_columns`).
void gravity_series(const Model& model, const std::vector<Sample>& samples, bool payload_columns,
                    std::vector<JointSeries>& series) {
  const int n = model.nq();
  const std::size_t N = samples.size();
  const std::size_t count = payload_columns ? 5 : 1;
  std::vector<Model> models(count, model);
  for (std::size_t c = 1; c < count; ++c) {
    Inertia unit;
    unit.mass = 1.0;
    if (c > 1) unit.com = Vector3::Unit(static_cast<Eigen::Index>(c - 2));
    auto& body = models[c].bodies[static_cast<std::size_t>(n)].inertia;
    body = body + unit;
  }
  for (JointSeries& js : series) {
    js.gravity.assign(N, 0.0);
    js.q.assign(N, 0.0);
    js.axis_along_gravity = true;
    if (payload_columns)
      for (std::vector<double>& p : js.payload_gravity) p.assign(N, 0.0);
  }
  std::array<VectorX, 5> g;
  std::vector<Data> data;  // one per model: Data caches its model's mass properties
  data.reserve(count);
  for (std::size_t c = 0; c < count; ++c) data.emplace_back(models[c]);
  Data poses(model);
  const double g_norm = model.gravity.norm();
  for (std::size_t k = 0; k < N; ++k) {
    for (std::size_t c = 0; c < count; ++c)
      g[c] = gravity_torques(models[c], data[c], samples[k].q);
    forward_poses(model, poses, samples[k].q);  // the axes in W: S_i's angular part
    for (int i = 0; i < n; ++i) {
      JointSeries& js = series[static_cast<std::size_t>(i)];
      const Vector3 axis = poses.S[static_cast<std::size_t>(i) + 1].tail<3>();
      if (g_norm > 0.0 && axis.cross(model.gravity).norm() > 1e-6 * g_norm * axis.norm())
        js.axis_along_gravity = false;
      js.gravity[k] = g[0][i];
      js.q[k] = samples[k].q[i];
      if (!payload_columns) continue;
      js.payload_gravity[0][k] = g[1][i] - g[0][i];
      for (std::size_t a = 1; a < 4; ++a) js.payload_gravity[a][k] = g[a + 1][i] - g[1][i];
    }
  }
  // About a vertical axis no mass gives a torque: what the pass computed there is rounding
  // (~1e-15 N m, yet it follows the configuration), which a regression would scale up into a
  // pattern ("-4e+14 times the model's gravity torque") or a nuisance column. Exactly zero.
  for (JointSeries& js : series) {
    if (!js.axis_along_gravity) continue;
    std::fill(js.gravity.begin(), js.gravity.end(), 0.0);
    for (std::vector<double>& p : js.payload_gravity) std::fill(p.begin(), p.end(), 0.0);
  }
}

// Whether most windows hold a reversal of their joint's velocity (or begin within 0.1 s after
// one): the signature of friction that lags the reversals (a Dahl sign), not of a contact.
bool most_follow_reversals(const std::vector<SuspectWindow>& windows,
                           const std::vector<Sample>& samples) {
  std::size_t following = 0;
  for (const SuspectWindow& w : windows) {
    const auto i = static_cast<Eigen::Index>(w.joint - 1);
    for (std::size_t k = 1; k < samples.size(); ++k) {
      if (samples[k].t < w.t_begin - kReversalLead) continue;
      if (samples[k].t > w.t_end) break;
      if ((samples[k].dq[i] > 0.0) != (samples[k - 1].dq[i] > 0.0)) {
        ++following;
        break;
      }
    }
  }
  return 2 * following > windows.size();
}

// Marks the samples inside the windows (and one settle time after each) as unused.
void exclude_windows(const std::vector<SuspectWindow>& windows, const std::vector<Sample>& samples,
                     double settle, std::vector<char>& use) {
  for (std::size_t k = 0; k < samples.size(); ++k)
    for (const SuspectWindow& w : windows)
      if (samples[k].t >= w.t_begin - kWindowGap && samples[k].t <= w.t_end + settle) use[k] = 0;
}

/// The fitted friction and offsets into `cal`, and per joint the residual's threshold for the
/// false-alarm rate, before (r0, the model's own friction) and after the fit: of the residual as
/// the detector sees it (through the residual filter, where one is configured).
void friction_and_thresholds(const std::vector<JointFrictionFit>& fits,
                             const std::vector<JointSeries>& series,
                             const std::vector<JointSeries>& before,
                             const std::vector<Sample>& samples, const std::vector<char>& use,
                             const CalibrationOptions& o, Calibration& cal) {
  const int n = static_cast<int>(fits.size());
  cal.friction = JointFriction::none(n);
  cal.friction.sign = o.sign;
  cal.friction.offset = VectorX::Zero(n);
  const bool dahl = o.sign == SmoothSign::kDahl;
  (dahl ? cal.friction.presliding : cal.friction.joint_smoothing) = VectorX::Zero(n);
  if (o.sign == SmoothSign::kSigmoid) cal.friction.velocity_shift = VectorX::Zero(n);
  cal.tau_threshold = VectorX::Zero(n);
  cal.residual_noise = VectorX::Zero(n);
  cal.tau_per_speed = VectorX::Zero(n);
  cal.inertia_correction = VectorX::Zero(n);
  const double rate = o.false_alarms_per_hour / 3600.0 / n;
  for (int i = 0; i < n; ++i) {
    const JointFrictionFit& f = fits[static_cast<std::size_t>(i)];
    cal.friction.viscous[i] = f.viscous;
    cal.friction.coulomb[i] = f.coulomb;
    cal.friction.offset[i] = f.offset;
    (dahl ? cal.friction.presliding : cal.friction.joint_smoothing)[i] = f.smoothing;
    if (o.sign == SmoothSign::kSigmoid) cal.friction.velocity_shift[i] = f.shift;
    cal.inertia_correction[i] = f.inertia;
    for (const std::string& w : f.warnings) cal.warnings.push_back(w);
    JointFitReport j;
    j.condition = f.condition;
    j.inertia_correction = f.inertia;
    j.inertia_gain = f.inertia_gain;
    JointFitReport b;
    joint_threshold(before[static_cast<std::size_t>(i)].r0, samples, use, rate, 1.0, b);
    j.rms_before = b.rms_after;
    j.max_before = b.max_after;
    joint_threshold(f.residual, samples, use, rate, o.threshold_margin, j);
    j.variance_explained =
        b.noise_std > 0 ? 1.0 - (j.noise_std * j.noise_std) / (b.noise_std * b.noise_std) : 0.0;
    j.threshold_constant = j.threshold;
    speed_threshold(f.residual, series[static_cast<std::size_t>(i)].dq, samples, use, rate,
                    o.threshold_margin, j);
    j.speed_dependent = j.threshold_per_speed > 0.0 &&
                        (o.thresholds == ThresholdModel::kSpeed ||
                         (o.thresholds == ThresholdModel::kAuto &&
                          j.mean_threshold_speed < kSpeedGain * j.threshold_constant));
    if (j.speed_dependent) {
      j.threshold = j.threshold_at_rest;
      cal.tau_per_speed[i] = j.threshold_per_speed;
    }
    cal.tau_threshold[i] = j.threshold;
    cal.residual_noise[i] = j.noise_std;
    cal.joints.push_back(j);
  }
}

}  // namespace

std::optional<SmoothSign> calibration_sign(std::string_view name) {
  if (name == "tanh") return SmoothSign::kTanh;
  if (name == "sigmoid") return SmoothSign::kSigmoid;
  if (name == "dahl") return SmoothSign::kDahl;
  return std::nullopt;
}

std::optional<ThresholdModel> threshold_model(std::string_view name) {
  if (name == "auto") return ThresholdModel::kAuto;
  if (name == "constant") return ThresholdModel::kConstant;
  if (name == "speed") return ThresholdModel::kSpeed;
  return std::nullopt;
}

namespace {

// calibrate() on validated options and samples, the momentum's q̇ given (empty: the log's).
Calibration calibrate_with(const Model& model, const EstimatorOptions& options,
                           const std::vector<Sample>& samples,
                           const std::vector<VectorX>& momentum_dq, const CalibrationOptions& o) {
  const int n = model.nq();
  const VectorX gains = MomentumObserver::checked_gains(options.observer_gain, n);
  const double settle =
      o.settle_time >= 0 ? o.settle_time : kSettleTimeConstants / gains.minCoeff();
  const int parameters = kParametersPerJoint * n + reading_size(options.sensor.type);
  std::vector<char> use(samples.size(), 0);
  for (std::size_t k = 0; k < samples.size(); ++k)
    use[k] = samples[k].t - samples.front().t >= settle - 1e-9 ? 1 : 0;
  const auto used = static_cast<int>(std::count(use.begin(), use.end(), 1));
  if (used < parameters) {
    throw Error("calibration: " + std::to_string(used) + " samples after the first " +
                number_text(settle) + " s (the residual's settling) for " +
                std::to_string(parameters) + " parameters: record a longer motion");
  }
  // The model the estimator will use: payload included.
  Model m = model;
  if (options.payload) {
    auto& body = m.bodies[static_cast<std::size_t>(options.payload->body)];
    body.inertia = body.inertia + options.payload->inertia;
  }
  Calibration cal;
  if (o.payload) {
    if (options.sensor.type == SensorType::kNone) {
      throw Error(
          "calibration: payload identification needs a base force/torque sensor or force sensor "
          "(sensor.type: ft | force; its force separates the payload's weight from the joints' "
          "offsets), this configuration has sensor.type: none");
    }
    if (options.payload && options.payload->body != n) {
      throw Error("calibration: the configuration has a payload on body " +
                  std::to_string(options.payload->body) +
                  "; payload identification is for the last link (" + std::to_string(n) + ")");
    }
    const calibration_detail::PayloadFit pf = calibration_detail::fit_payload(
        m, options.sensor.X_WS, n, options.sensor.type == SensorType::kForceTorque,
        o.smoothing_velocity > 0 ? o.smoothing_velocity : 0.01, samples, use);
    cal.payload.identified = true;
    cal.payload.body = n;
    cal.payload.mass = pf.mass;
    cal.payload.com = pf.first_moment / pf.mass;
    cal.payload.rms_before = pf.rms_before;
    cal.payload.rms_after = pf.rms_after;
    cal.payload.condition = pf.condition;
    cal.payload.samples = pf.samples;
    Inertia identified;
    identified.mass = pf.mass;
    identified.com = cal.payload.com;
    auto& body = m.bodies[static_cast<std::size_t>(n)];
    body.inertia = body.inertia + identified;
  }
  std::vector<JointSeries> series, before;
  run_observer(m, gains, JointFriction::none(n), samples, momentum_dq, series, false);
  run_observer(m, gains, options.friction ? *options.friction : JointFriction::from_model(model),
               samples, momentum_dq, before, true);
  if (o.known_external_torque) {
    for (std::size_t i = 0; i < series.size(); ++i)
      remove_known_torque(samples, static_cast<int>(i), series[i], before[i]);
  }

  gravity_series(m, samples, o.inertia_correction, series);
  momentum_series(m, samples, momentum_dq, series);
  cal.observer_gain = gains;
  cal.residual_cutoff = per_joint(options.residual_cutoff, n);
  // The residual filter: every series from here on is the filtered residual (r is linear in θ,
  // so filtering r⁰ and each regressor gives the estimator's filtered residual, to rounding).
  for (int i = 0; i < n; ++i) {
    const double cutoff = cal.residual_cutoff[i];
    if (!(cutoff > 0.0)) continue;
    const std::vector<double> weight = calibration_detail::residual_filter_weights(samples, cutoff);
    for (std::vector<JointSeries>* s : {&series, &before}) {
      JointSeries& js = (*s)[static_cast<std::size_t>(i)];
      calibration_detail::apply_residual_filter(weight, js.r0);
      js.filter_weight = weight;
    }
  }
  momentum_fast_series(samples, series);
  cal.sensor_type = options.sensor.type;
  cal.false_alarms_per_hour = o.false_alarms_per_hour;
  cal.t_begin = samples.front().t;
  cal.t_end = samples.back().t;
  // With the Dahl sign the fixed scale is a displacement δ [rad], not a velocity.
  const double check_smoothing =
      o.sign != SmoothSign::kDahl && o.smoothing_velocity > 0 ? o.smoothing_velocity : 0.01;
  std::vector<JointFrictionFit> fits(static_cast<std::size_t>(n));
  // Contacts are looked for in the residual of friction alone: an inertia correction could
  // absorb a push's part that follows q̈. The final fit, on the samples kept, adds it.
  CalibrationOptions friction_only = o;
  friction_only.inertia_correction = false;
  const auto fit_all = [&](const CalibrationOptions& fo) {
    for (int i = 0; i < n; ++i) {
      const auto& s = series[static_cast<std::size_t>(i)];
      calibration_detail::check_excitation(s, use, i + 1, check_smoothing);
      fits[static_cast<std::size_t>(i)] = calibration_detail::fit_joint(s, use, fo, i + 1);
    }
  };
  for (int pass = 0; pass < 2; ++pass) {
    fit_all(pass == 0 ? friction_only : o);
    if (pass == 1) break;
    // Short strong contacts, and long ones that the fit has partly absorbed (half the level,
    // ten times the duration).
    cal.suspect_windows =
        suspect_windows(fits, samples, use, o.contact_sigma, o.contact_min_duration);
    for (const SuspectWindow& w :
         suspect_windows(fits, samples, use, 0.5 * o.contact_sigma, 10.0 * o.contact_min_duration))
      cal.suspect_windows.push_back(w);
    if (cal.suspect_windows.empty()) {
      if (o.inertia_correction) fit_all(o);
      break;
    }
    exclude_windows(cal.suspect_windows, samples, settle, use);
    const auto left = static_cast<int>(std::count(use.begin(), use.end(), 1));
    std::string list;
    for (const SuspectWindow& w : cal.suspect_windows)
      list += " [" + time_text(w.t_begin) + ", " + time_text(w.t_end) + "] s (joint " +
              std::to_string(w.joint) + ", " + number_text(w.peak, 3) + " N m)";
    if (used - left > o.max_contact_fraction * used || left < parameters) {
      std::string hint = "; record free motion only";
      if (o.sign != SmoothSign::kDahl && most_follow_reversals(cal.suspect_windows, samples))
        hint +=
            ". Most windows hold a reversal of their joint's velocity: friction that lags the "
            "velocity's reversals looks like this (calibrate with --sign dahl, "
            "docs/calibration.md)";
      throw Error(
          "calibration: the log does not look contact-free: the residual is far above "
          "its noise during" +
          list + hint);
    }
    cal.warnings.push_back(
        "possible contact (residual far above its noise), excluded from the "
        "fit:" +
        list);
  }
  cal.samples_used = static_cast<int>(std::count(use.begin(), use.end(), 1));
  friction_and_thresholds(fits, series, before, samples, use, o, cal);
  warn_unexplained_torque(samples, use, cal);
  calibration_detail::check_joints(series, before, fits, samples, cal.residual_cutoff,
                                   per_joint(options.velocity_cutoff, n), use, cal.model_check);
  if (options.sensor.type != SensorType::kNone)
    sensor_calibration(model, options, samples, use, o, cal);
  // A base moment linear in the configuration is a sensor pose error only when the joints do
  // not follow g(q) too: a mass error moves both, a sensor pose the sensor alone.
  auto& patterns = cal.model_check.patterns;
  const bool gravity = std::any_of(patterns.begin(), patterns.end(),
                                   [](const ModelPattern& p) { return p.kind == "gravity"; });
  if (gravity) {
    patterns.erase(std::remove_if(patterns.begin(), patterns.end(),
                                  [](const ModelPattern& p) { return p.kind == "sensor_pose"; }),
                   patterns.end());
  }
  return cal;
}

}  // namespace

bool add_identified_payload(const Calibration& calibration, EstimatorOptions& options) {
  if (!calibration.payload.identified) return true;
  Inertia identified;
  identified.mass = calibration.payload.mass;
  identified.com = calibration.payload.com;
  if (!options.payload) {
    options.payload = PayloadOptions{calibration.payload.body, identified};
  } else if (options.payload->body == calibration.payload.body) {
    options.payload->inertia = options.payload->inertia + identified;
  } else {
    return false;
  }
  return true;
}

// The momentum's q̇ through the estimator's velocity filter (as ContactEstimator::update does),
// then the calibration of the log.
Calibration calibrate(const Model& model, const EstimatorOptions& options,
                      const std::vector<Sample>& samples, const CalibrationOptions& o) {
  const int n = model.nq();
  validate(options, model);
  if (o.known_external_torque && options.sensor.type != SensorType::kNone) {
    throw Error(
        "calibration: a known external torque is for configurations without a base sensor "
        "(sensor.type: none): the sensor's bias would absorb the contact force");
  }
  check_samples(samples, n, o.known_external_torque);
  ResidualFilter velocity(options.velocity_cutoff, n);
  std::vector<VectorX> momentum_dq;
  if (velocity.enabled()) {
    momentum_dq.reserve(samples.size());
    velocity.reset(samples.front().dq);
    momentum_dq.push_back(samples.front().dq);
    for (std::size_t k = 1; k < samples.size(); ++k) {
      momentum_dq.push_back(samples[k].dq);
      velocity.apply(samples[k].t - samples[k - 1].t, momentum_dq.back());
    }
  }
  Calibration cal = calibrate_with(model, options, samples, momentum_dq, o);
  cal.velocity_cutoff = velocity.enabled() ? velocity.cutoff() : VectorX::Zero(n);
  return cal;
}

EstimatorOptions apply_calibration(EstimatorOptions options, const Calibration& calibration) {
  if (!add_identified_payload(calibration, options)) {
    throw Error("calibration: the identified payload is on body " +
                std::to_string(calibration.payload.body) + ", the configured one on body " +
                std::to_string(options.payload->body));
  }
  options.friction = calibration.friction;
  if (calibration.residual_cutoff.size() > 0)  // the thresholds are for its output
    options.residual_cutoff = calibration.residual_cutoff;
  if (calibration.velocity_cutoff.size() > 0)  // and for the q̇ it saw
    options.velocity_cutoff = calibration.velocity_cutoff;
  if (calibration.inertia_correction.size() > 0)  // part of the residual the fit minimised
    options.inertia_correction = calibration.inertia_correction;
  options.detection.tau_min = calibration.tau_threshold;
  options.detection.tau_per_speed = calibration.tau_per_speed;
  if (calibration.sensor_type != SensorType::kNone && calibration.force_threshold > 0) {
    options.detection.f_min = calibration.force_threshold;
    options.sensor.bias_S = calibration.sensor_bias_S;
  }
  return options;
}

}  // namespace extwrench
