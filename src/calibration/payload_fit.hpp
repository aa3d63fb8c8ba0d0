// Calibration internals: the payload on a link from the base sensor's wrench (payload.cpp).
#pragma once

#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::calibration_detail {

struct PayloadFit {
  double mass = 0.0;                       ///< [kg]
  Vector3 first_moment = Vector3::Zero();  ///< h = m c in the body's frame [kg m]
  Vector6 bias_S = Vector6::Zero();        ///< sensor bias fitted with it [f; n] (S)
  Vector6 rms_before = Vector6::Zero();    ///< per axis, reading − model − mean [N | N m]
  Vector6 rms_after = Vector6::Zero();     ///< per axis, after payload and bias
  double condition = 0.0;                  ///< of the column-scaled regression
  int samples = 0;
};

/// The payload on `body` (mass, first moment) and the sensor bias, by least squares on
/// reading_S − predicted reading over the samples with use[k], q̈ from a central difference of
/// q̇. Throws extwrench::Error when too few samples, not excited, or the mass is not positive.
[[nodiscard]] PayloadFit fit_payload(const Model& model, const Pose& X_WS, int body,
                                     const std::vector<Sample>& samples,
                                     const std::vector<char>& use);

}  // namespace extwrench::calibration_detail
