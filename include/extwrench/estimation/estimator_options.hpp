// The ContactEstimator's options and validate(), the one place where their ranges, sizes and
// indices are checked against a model.
#pragma once

#include <optional>

#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/estimation/damped_least_squares.hpp"
#include "extwrench/estimation/detection.hpp"
#include "extwrench/estimation/isolation.hpp"
#include "extwrench/estimation/uncertainty.hpp"
#include "extwrench/model/model.hpp"
#include "extwrench/observer/friction.hpp"

namespace extwrench {

struct SensorOptions {
  SensorType type = SensorType::kNone;
  Pose X_WS;  ///< pose of the sensor frame in the robot's root frame
  int tare_samples =
      0;  ///< > 0: bias = mean(reading − predicted) over the first samples after reset
  Vector6 bias_S = Vector6::Zero();  ///< bias [f; n] in S at the start (calibration); a tare
                                     ///< replaces it
};

struct ContactOptions {
  ContactModel model = ContactModel::kPureForce;
  int link = -1;                      ///< known point: body index of the contact link
  Vector3 point_L = Vector3::Zero();  ///< known point: p in the link frame L [m]
};

struct PayloadOptions {
  int body = -1;    ///< body carrying the payload
  Inertia inertia;  ///< mass properties in that body's frame
};

/// Slow drift tracking (docs/estimator.md#drift-tracking): while no contact is declared (and the
/// residual has settled since the last one), the joint torque offsets and the base sensor's bias
/// follow what is left in the residual and in F̂_ext, as first-order filters of time constant
/// `time_constant`, each entry moving at most at its rate; frozen during contact.
struct DriftOptions {
  double time_constant = 30.0;     ///< [s] > 0
  double max_torque_rate = 0.01;   ///< [N m/s] (N/s prismatic) > 0, per joint offset
  double max_force_rate = 0.05;    ///< [N/s] > 0, per sensor force axis
  double max_moment_rate = 0.005;  ///< [N m/s] > 0, per sensor moment axis
};

struct EstimatorOptions {
  SensorOptions sensor;
  ContactOptions contact;
  VectorX observer_gain = VectorX::Constant(1, 100.0);  ///< K [1/s], size 1 or n
  DetectionOptions detection;
  IsolationOptions isolation;  ///< which rule picks the contact link (isolation.hpp)
  AccelerationRoute acceleration = AccelerationRoute::kResidual;
  double differentiation_cutoff = 50.0;  ///< [Hz] low-pass of the differentiated q̇ (route (a))
  /// [Hz] ≥ 0, size 1 or n: second-order low-pass of τ̂_ext before stages 5–9 per joint
  /// (residual_filter.hpp); 0: none. For real arms whose q̇ noise reaches r through K B(q) δq̇
  /// (docs/estimator.md#residual-filter).
  VectorX residual_cutoff = VectorX::Zero(1);
  /// [Hz] ≥ 0, size 1 or n: the same second-order low-pass on the q̇ of the momentum pass
  /// (p = B(q) q̇, Cᵀq̇, the bias terms); friction, q̈'s differentiation and the thresholds keep
  /// the measured q̇; 0: none. It removes the velocity's noise that the observer passes as
  /// K B(q) δq̇ while a torque-borne τ_ext keeps the observer's own bandwidth
  /// (docs/estimator.md#velocity-filter). Not applied by update_with (q̇ as given).
  VectorX velocity_cutoff = VectorX::Zero(1);
  /// δI [kg m² | kg], size 1 or n, finite, any sign: added to the momentum the observer
  /// differentiates, p = B(q) q̇ + δI q̇ (a constant error of the inertia along each joint,
  /// identified by `extwrench calibrate`), and to B(q)'s diagonal where q̈̂ is solved from the
  /// residual (route (b)); 0: none (docs/calibration.md#inertia-correction).
  VectorX inertia_correction = VectorX::Zero(1);
  std::optional<JointFriction> friction;  ///< default: the model's Joint::damping / friction
  std::optional<PayloadOptions> payload;
  SolverOptions solver;
  std::optional<DriftOptions> drift;  ///< opt-in; none: offsets and bias stay as configured
  UncertaintyOptions uncertainty;     ///< noise levels and the `uncertain` flag (uncertainty.hpp)
};

/// Throws extwrench::Error if the options do not fit the model (sizes, link indices, ranges,
/// finite payload) or the model is not a serial chain (isolation by joint index needs one).
/// The ContactEstimator's constructor calls it first.
void validate(const EstimatorOptions& options, const Model& model);

/// Mass properties usable as a payload: finite, mass ≥ 0.
[[nodiscard]] bool finite_inertia(const Inertia& in) noexcept;

}  // namespace extwrench
