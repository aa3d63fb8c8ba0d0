#include "extwrench/estimation/estimator_options.hpp"

#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/observer/momentum_observer.hpp"

namespace extwrench {
namespace {

void validate_contact(const ContactOptions& c, const Model& model, const std::string& where) {
  if (c.model != ContactModel::kKnownPoint) return;
  if (c.link < 0 || c.link >= model.num_bodies()) {
    throw Error(where + ": contact.link: body index " + std::to_string(c.link) + " is not in [0, " +
                std::to_string(model.num_bodies() - 1) + "]");
  }
  if (!c.point_L.allFinite()) throw Error(where + ": contact.point: expected finite values");
}

void validate_sensor(const SensorOptions& s, const std::string& where) {
  const Pose& X = s.X_WS;
  if (!X.translation.allFinite() || !X.rotation.allFinite() ||
      !(X.rotation * X.rotation.transpose()).isIdentity(1e-9) || X.rotation.determinant() < 0) {
    throw Error(where + ": sensor.pose: expected a finite rigid transform");
  }
  if (s.tare_samples < 0) throw Error(where + ": sensor.tare: expected a sample count >= 0");
  if (!s.bias_S.allFinite()) throw Error(where + ": sensor.bias: expected finite values");
}

// observer.KEY (a residual or velocity filter's cutoffs [Hz]): finite values >= 0; with the
// model's n, also 1 or n of them.
void validate_cutoffs(const VectorX& cutoff, const char* key, const std::string& where, int n = 0) {
  if (!(cutoff.array() >= 0.0).all() || !cutoff.allFinite()) {
    throw Error(where + ": observer." + key + ": expected finite values >= 0 [Hz] (0: none)");
  }
  if (n > 0 && cutoff.size() != 1 && cutoff.size() != n) {
    throw Error(where + ": observer." + key + ": expected 1 or " + std::to_string(n) +
                " values, got " + std::to_string(cutoff.size()));
  }
}

void validate_numerics(const EstimatorOptions& o, const std::string& where) {
  if (!(o.differentiation_cutoff > 0.0) || !std::isfinite(o.differentiation_cutoff)) {
    throw Error(where + ": acceleration cutoff: expected a finite value > 0 [Hz]");
  }
  validate_cutoffs(o.residual_cutoff, "residual_cutoff", where);
  validate_cutoffs(o.velocity_cutoff, "velocity_cutoff", where);
  if (!(o.solver.max_condition > 1.0) || !std::isfinite(o.solver.max_condition)) {
    throw Error(where + ": solver.max_condition: expected a finite value > 1");
  }
  if (!(o.solver.rank_tolerance > 0.0 && o.solver.rank_tolerance < 1.0)) {
    throw Error(where + ": solver.rank_tolerance: expected a value in (0, 1)");
  }
  if (!(o.isolation.tolerance > 0.0) || !std::isfinite(o.isolation.tolerance)) {
    throw Error(where + ": isolation.tolerance: expected a finite value > 0");
  }
  if (!(o.isolation.ambiguity_distance >= 0.0) || !std::isfinite(o.isolation.ambiguity_distance)) {
    throw Error(where + ": isolation.ambiguity_distance: expected a finite value >= 0 [m]");
  }
  if (!(o.isolation.misfit_margin >= 0.0) || !std::isfinite(o.isolation.misfit_margin)) {
    throw Error(where + ": isolation.misfit_margin: expected a finite value >= 0");
  }
  if (o.drift) {
    const auto positive = [&](double v, const char* name) {
      if (!(v > 0.0) || !std::isfinite(v))
        throw Error(where + ": drift." + name + ": expected a finite value > 0");
    };
    positive(o.drift->time_constant, "time_constant");
    positive(o.drift->max_torque_rate, "max_torque_rate");
    positive(o.drift->max_force_rate, "max_force_rate");
    positive(o.drift->max_moment_rate, "max_moment_rate");
  }
}

void validate_uncertainty(const UncertaintyOptions& u, int n, const std::string& where) {
  const VectorX& s = u.residual_sigma;
  if (s.size() != 1 && s.size() != n) {
    throw Error(where + ": uncertainty.residual_sigma: expected 1 or " + std::to_string(n) +
                " values, got " + std::to_string(s.size()));
  }
  const auto non_negative = [](const auto& v) { return v.allFinite() && (v.array() >= 0.0).all(); };
  if (!non_negative(s))
    throw Error(where + ": uncertainty.residual_sigma: expected finite values >= 0 [N m]");
  if (!non_negative(u.sensor_force_sigma))
    throw Error(where + ": uncertainty.sensor_force_sigma: expected finite values >= 0 [N]");
  if (!non_negative(u.sensor_moment_sigma))
    throw Error(where + ": uncertainty.sensor_moment_sigma: expected finite values >= 0 [N m]");
  if (!(u.uncertain_fraction > 0.0) || !std::isfinite(u.uncertain_fraction))
    throw Error(where + ": uncertainty.uncertain_fraction: expected a finite value > 0");
  if (!(u.uncertain_sigmas > 0.0) || !std::isfinite(u.uncertain_sigmas))
    throw Error(where + ": uncertainty.uncertain_sigmas: expected a finite value > 0");
}

}  // namespace

bool finite_inertia(const Inertia& in) noexcept {
  return std::isfinite(in.mass) && in.mass >= 0.0 && in.com.allFinite() &&
         in.inertia_com.allFinite();
}

void validate(const EstimatorOptions& o, const Model& model) {
  const std::string where = "estimator for robot '" + model.name + "'";
  if (!model.is_serial_chain()) {
    throw Error(where + ": the model is not a serial chain (isolation by joint index needs one); " +
                describe_branches(model) +
                ". Lock the joints of all branches but one: --lock NAME=VALUE on the command "
                "line, or locked_joints: {NAME: VALUE} in the configuration or scenario");
  }
  validate_contact(o.contact, model, where);
  validate_sensor(o.sensor, where);
  validate_numerics(o, where);
  if (o.payload && (o.payload->body < 0 || o.payload->body >= model.num_bodies())) {
    throw Error(where + ": payload.link: body index " + std::to_string(o.payload->body) +
                " is not in the model");
  }
  // The observer's and the detector's own checks, in the order the estimator builds them.
  const int n = model.nq();
  if (n < 1) throw Error("MomentumObserver: model '" + model.name + "' has no joint");
  validate_uncertainty(o.uncertainty, n, where);
  (void)MomentumObserver::checked_gains(o.observer_gain, n);
  validate_friction(JointFriction::from_model(model), n,
                    "MomentumObserver: model '" + model.name + "'");
  validate(o.detection, n);
  validate_cutoffs(o.residual_cutoff, "residual_cutoff", where, n);
  validate_cutoffs(o.velocity_cutoff, "velocity_cutoff", where, n);
  (void)MomentumObserver::checked_inertia_correction(o.inertia_correction, n);
  if (o.friction) validate_friction(*o.friction, n, "MomentumObserver");
  if (o.payload && !finite_inertia(o.payload->inertia)) {
    throw Error(where + ": payload: non-finite or negative mass properties");
  }
}

}  // namespace extwrench
