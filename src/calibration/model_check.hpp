// Calibration internals: the model check (docs/calibration.md#model-check): the model's
// prediction error in free motion and the recognisable patterns in it.
#pragma once

#include <vector>

#include "extwrench/calibration/calibration.hpp"
#include "friction_fit.hpp"

namespace extwrench::calibration_detail {

/// Joint patterns. before[i].r0: the residual with the model as configured; after[i]: the
/// calibrated residual; series[i]: q̇, g_i(q_k) and the observer's filter; samples: the log
/// (its time stamps); residual_cutoff, velocity_cutoff: the configured residual and velocity
/// filters per joint (n).
void check_joints(const std::vector<JointSeries>& series, const std::vector<JointSeries>& before,
                  const std::vector<JointFrictionFit>& after, const std::vector<Sample>& samples,
                  const VectorX& residual_cutoff, const VectorX& velocity_cutoff,
                  const std::vector<char>& use, ModelCheck& check);

/// Base-sensor patterns from error_S = reading − predicted (no bias) and predicted_S, per used
/// sample; `moments`: a 6-axis sensor.
void check_sensor(const std::vector<Vector6>& error_S, const std::vector<Vector6>& predicted_S,
                  bool moments, ModelCheck& check);

}  // namespace extwrench::calibration_detail
