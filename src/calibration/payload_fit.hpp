// Calibration internals: the payload on a link from the base sensor's wrench and the joint
// torques (payload.cpp).
#pragma once

#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::calibration_detail {

struct PayloadFit {
  double mass = 0.0;                          ///< [kg]
  Vector3 first_moment = Vector3::Zero();     ///< h = m c in the body's frame [kg m]
  Vector6 bias_S = Vector6::Zero();           ///< sensor bias fitted with it [f; n] (S)
  VectorX joint_rms_before, joint_rms_after;  ///< τ − model per joint, friction fitted [N m]
  Vector6 rms_before = Vector6::Zero();       ///< per axis, reading − model − mean [N | N m]
  Vector6 rms_after = Vector6::Zero();        ///< per axis, after payload and bias
  double condition = 0.0;                     ///< of the column-scaled regression
  int samples = 0;
};

/// The payload on `body` (mass, first moment) and the sensor bias, by weighted least squares on
/// the base reading and the joint torques together over the samples with use[k], q̈ from a
/// central difference of q̇:
///   reading_S − predicted_S = Y_m m + Y_h h + bias            (6 rows; 3 for a force sensor)
///   τ − τ_model             = Y_τm m + Y_τh h + D q̇ + F_c s(q̇) + o   (n rows; friction and
///                                                               offsets as nuisance parameters)
/// Each row group (sensor axis, joint) is weighted by the inverse RMS of its first-pass misfit.
/// `moments`: a 6-axis sensor; else the CoM comes from the joint torques alone.
/// `smoothing_velocity` [rad/s]: v_s of the Coulomb nuisance term s = tanh(q̇ / v_s). Throws
/// extwrench::Error when too few samples, not excited, or the mass is not positive.
[[nodiscard]] PayloadFit fit_payload(const Model& model, const Pose& X_WS, int body, bool moments,
                                     double smoothing_velocity, const std::vector<Sample>& samples,
                                     const std::vector<char>& use);

}  // namespace extwrench::calibration_detail
