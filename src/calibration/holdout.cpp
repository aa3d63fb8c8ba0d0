#include "extwrench/calibration/holdout.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/contact_estimator.hpp"

namespace extwrench {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The lever point of body `link`: `lever` metres from its origin along a direction ⊥ its axis.
Vector3 lever_point(const Model& model, const Data& data, int link, double lever) {
  const Vector3& axis = model.joints[static_cast<std::size_t>(link)].axis;
  Vector3 across = axis.cross(Vector3::UnitX());
  if (across.norm() < 0.1) across = axis.cross(Vector3::UnitY());
  const Pose& X_WL = data.X_WB[static_cast<std::size_t>(link)];
  return X_WL.act(lever * across.normalized());
}

}  // namespace

double smallest_detectable_force(const Model& model, const Data& data, int link, const Vector3& p_W,
                                 const VectorX& tau_min) {
  Matrix6X J = Matrix6X::Zero(6, model.nq());
  point_jacobian(model, data, link, p_W, J);
  double best = 0.0;  // max_i ‖J_v,i‖ / τ_min,i: joint i feels a unit force along J_v,i best
  for (int i = 0; i < model.nq(); ++i)
    best = std::max(best, J.col(i).head<3>().norm() / tau_min[i]);
  return best > 0 ? 1.0 / best : std::numeric_limits<double>::infinity();
}

HoldoutReport validate_holdout(const Model& model, const EstimatorOptions& options,
                               const Calibration& calibration, const std::vector<Sample>& samples,
                               std::size_t first, double lever) {
  if (first >= samples.size()) throw Error("holdout: no sample after the fit window");
  const int n = model.nq();
  ContactEstimator plain(model, GeometryModel{}, options);
  const EstimatorOptions calibrated_options = apply_calibration(options, calibration);
  ContactEstimator calibrated(model, GeometryModel{}, calibrated_options);
  HoldoutReport rep;
  rep.lever = lever;
  rep.calibrated_threshold = calibration.tau_threshold;
  rep.calibrated_per_speed =
      calibration.tau_per_speed.size() == n ? calibration.tau_per_speed : VectorX::Zero(n);
  rep.calibrated_constant_threshold = calibration.tau_threshold;
  for (int i = 0; i < n && static_cast<std::size_t>(i) < calibration.joints.size(); ++i) {
    const JointFitReport& j = calibration.joints[static_cast<std::size_t>(i)];
    if (j.speed_dependent) rep.calibrated_constant_threshold[i] = j.threshold_constant;
  }
  EstimatorOptions constant_options = calibrated_options;
  constant_options.detection.tau_min = rep.calibrated_constant_threshold;
  constant_options.detection.tau_per_speed.resize(0);
  ContactEstimator constant_est(model, GeometryModel{}, constant_options);
  const bool speed = (rep.calibrated_per_speed.array() > 0.0).any();
  rep.best_constant_threshold = VectorX::Zero(n);
  rep.calibrated_max_residual = VectorX::Zero(n);
  const bool known_torque =
      std::all_of(samples.begin() + static_cast<std::ptrdiff_t>(first), samples.end(),
                  [](const Sample& s) { return s.has_true_tau_ext; });
  VectorX sum_sq_plain = VectorX::Zero(n), sum_sq_cal = VectorX::Zero(n);
  if (!plain.reset(samples.front()).ok() || !calibrated.reset(samples.front()).ok() ||
      (speed && !constant_est.reset(samples.front()).ok()))
    throw Error("holdout: estimator reset failed on the first sample");
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const bool ok_plain = plain.update(samples[k]).ok();
    const bool ok_cal = calibrated.update(samples[k]).ok();
    const bool ok_const = !speed || constant_est.update(samples[k]).ok();
    if (k < first || !ok_plain || !ok_cal || !ok_const) continue;
    ++rep.samples;
    if (plain.result().contact) ++rep.uncalibrated_false_alarms;
    if (calibrated.result().contact) ++rep.false_alarms;
    if (speed ? constant_est.result().contact : calibrated.result().contact)
      ++rep.constant_threshold_false_alarms;
    if (calibrated.detector().result().raw) ++rep.raw_alarms;
    rep.best_constant_threshold =
        rep.best_constant_threshold.cwiseMax(plain.result().residual.cwiseAbs());
    rep.calibrated_max_residual =
        rep.calibrated_max_residual.cwiseMax(calibrated.result().residual.cwiseAbs());
    if (known_torque) {
      sum_sq_plain += (plain.result().residual - samples[k].truth.tau_ext).cwiseAbs2();
      sum_sq_cal += (calibrated.result().residual - samples[k].truth.tau_ext).cwiseAbs2();
    }
  }
  if (known_torque && rep.samples > 0) {
    rep.tracking_rms_uncalibrated = (sum_sq_plain / rep.samples).cwiseSqrt();
    rep.tracking_rms_calibrated = (sum_sq_cal / rep.samples).cwiseSqrt();
  }
  rep.duration = samples.back().t - samples[first].t;
  // Detectable force along the holdout, with either set of thresholds.
  const VectorX constant = rep.best_constant_threshold.cwiseMax(1e-9);
  const VectorX quiet = rep.calibrated_max_residual.cwiseMax(1e-9);
  Data data(model);
  std::vector<std::vector<double>> cal_f(static_cast<std::size_t>(n) + 1),
      const_f(static_cast<std::size_t>(n) + 1), quiet_f(static_cast<std::size_t>(n) + 1),
      cal_const_f(static_cast<std::size_t>(n) + 1);
  VectorX threshold(n);
  for (std::size_t k = first; k < samples.size(); ++k) {
    forward_kinematics(model, data, samples[k].q);
    threshold =
        rep.calibrated_threshold + rep.calibrated_per_speed.cwiseProduct(samples[k].dq.cwiseAbs());
    for (int l = 1; l <= n; ++l) {
      const Vector3 p_W = lever_point(model, data, l, lever);
      const auto li = static_cast<std::size_t>(l);
      cal_f[li].push_back(smallest_detectable_force(model, data, l, p_W, threshold));
      cal_const_f[li].push_back(
          smallest_detectable_force(model, data, l, p_W, rep.calibrated_constant_threshold));
      const_f[li].push_back(smallest_detectable_force(model, data, l, p_W, constant));
      quiet_f[li].push_back(smallest_detectable_force(model, data, l, p_W, quiet));
    }
  }
  rep.min_force_calibrated.assign(static_cast<std::size_t>(n) + 1, 0.0);
  rep.min_force_constant.assign(static_cast<std::size_t>(n) + 1, 0.0);
  rep.min_force_calibrated_quiet.assign(static_cast<std::size_t>(n) + 1, 0.0);
  rep.min_force_calibrated_constant.assign(static_cast<std::size_t>(n) + 1, 0.0);
  for (int l = 1; l <= n; ++l) {
    const auto li = static_cast<std::size_t>(l);
    rep.min_force_calibrated_constant[li] = median(cal_const_f[li]);
    rep.min_force_calibrated[li] = median(cal_f[li]);
    rep.min_force_constant[li] = median(const_f[li]);
    rep.min_force_calibrated_quiet[li] = median(quiet_f[li]);
  }
  return rep;
}

}  // namespace extwrench
