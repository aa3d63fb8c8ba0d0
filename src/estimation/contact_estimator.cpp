#include "extwrench/estimation/contact_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/core/input_checks.hpp"
#include "extwrench/core/time_step.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/localization.hpp"
#include "extwrench/geometry/ray.hpp"

namespace extwrench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Time stamps are sums of floating steps: a duration reached up to this slack counts as reached.
constexpr double kTimeSlack = 1e-9;  // [s]
// A residual / filter transient is over after this many time constants (e^{-5} < 1 %).
constexpr double kSettleTimeConstants = 5.0;

/// How long the residual (or the differentiation filter) takes to forget a force that ended,
/// with the residual filter's two sections after it.
double settle_time_of(const EstimatorOptions& options, const MomentumObserver& observer) {
  const double slowest = options.acceleration == AccelerationRoute::kResidual
                             ? 1.0 / observer.gains().minCoeff()
                             : 1.0 / (2.0 * std::numbers::pi * options.differentiation_cutoff);
  // The slowest filtered joint's two sections, of the residual and of the velocity (in series
  // for a force that moves the arm).
  const auto slowest_filter = [](const VectorX& cutoffs) {
    double time = 0.0;
    for (const double cutoff : cutoffs)
      if (cutoff > 0.0) time = std::max(time, 2.0 / (2.0 * std::numbers::pi * cutoff));
    return time;
  };
  const double filter =
      slowest_filter(options.residual_cutoff) + slowest_filter(options.velocity_cutoff);
  return std::max(kSettleTimeConstants * (slowest + filter), options.detection.min_duration);
}

// LDLᵀ of B into `factor` and x ← B⁻¹ x, for N joints (6 or 7: most arms) in fixed-size copies
// whose loops the compiler unrolls: the operations and their order are the general path's, so
// the bits are too.
template <int N, typename Factor>
bool factor_and_solve_fixed(const MatrixX& B, Factor& factor, VectorX& x) noexcept {
  Eigen::Matrix<double, N, N> A = B;
  if (!ldlt_in_place(A)) return false;  // `factor` is then never read (root_wrench_dddq_valid_)
  Eigen::Matrix<double, N, 1> y = x;
  ldlt_solve(A, y);
  x = y;
  factor = A;
  return true;
}

}  // namespace

void ContactEstimator::warm_up() const noexcept { warm_up_geometry(geometry_); }

ContactEstimator::ContactEstimator(Model model, GeometryModel geometry, EstimatorOptions options)
    : options_(std::move(options)),
      model_((validate(options_, model), std::move(model))),
      data_(model_),
      geometry_(std::move(geometry)),
      observer_(model_, options_.observer_gain),
      residual_filter_(options_.residual_cutoff, model_.nq()),
      velocity_filter_(options_.velocity_cutoff, model_.nq()),
      dq_filtered_(VectorX::Zero(model_.nq())),
      detector_(options_.detection, model_.nq(), settle_time_of(options_, observer_)),
      isolation_ws_(model_),
      noise_(make_noise_model(options_.uncertainty, model_.nq(), options_.sensor.X_WS.rotation)),
      n_(model_.nq()),
      differentiation_(options_.acceleration == AccelerationRoute::kDifferentiation),
      need_ddq_(options_.sensor.type != SensorType::kNone || differentiation_) {
  if (geometry_.body_shapes.empty())
    geometry_.body_shapes.resize(static_cast<std::size_t>(model_.num_bodies()));
  if (static_cast<int>(geometry_.body_shapes.size()) != model_.num_bodies()) {
    throw Error("estimator for robot '" + model_.name + "': the collision geometry has " +
                std::to_string(geometry_.body_shapes.size()) + " bodies, the model " +
                std::to_string(model_.num_bodies()));
  }
  isolation_rule_ = resolved_rule(options_.isolation, geometry_);
  warm_up_geometry(geometry_);  // else the first contact pages in the ray casting code
  nominal_inertia_.reserve(model_.bodies.size());
  for (const Body& b : model_.bodies) nominal_inertia_.push_back(b.inertia);
  if (options_.friction) observer_.set_friction(*options_.friction);
  observer_.set_inertia_correction(options_.inertia_correction);
  inertia_corrected_ = !observer_.inertia_correction().isZero(0.0);
  tare_.bias_S = options_.sensor.bias_S;  // a calibrated bias (zero by default)
  if (options_.payload) apply_payload(options_.payload->body, &options_.payload->inertia);
  settle_time_ = settle_time_of(options_, observer_);
  dq_prev_ = VectorX::Zero(n_);
  ddq_filtered_ = VectorX::Zero(n_);
  ddq_ = VectorX::Constant(n_, kNaN);
  tau_ext_ = VectorX::Zero(n_);
  b_ = VectorX::Zero(n_);
  tau_pred_ = VectorX::Zero(n_);
  tau_eff_ = VectorX::Zero(n_);
  dynamic_torque_ = VectorX::Zero(n_);
  J_ = Matrix6X::Zero(6, n_);
  root_wrench_dddq_ = Matrix6X::Zero(6, n_);
  minv_jvt_r_.setZero(n_, 4);
  out_.residual = VectorX::Zero(n_);
  if (options_.drift) {
    JointFriction friction = observer_.friction();
    if (friction.offset.size() != n_) {
      friction.offset = VectorX::Zero(n_);
      observer_.set_friction(friction);
    }
    initial_offset_ = friction.offset;
    drift_delta_ = VectorX::Zero(n_);
    out_.torque_offset = initial_offset_;
  }
}

Status ContactEstimator::reset(double t, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq,
                               const Eigen::Ref<const VectorX>& tau) noexcept {
  // A moved-from estimator has no model left (nq -1): nothing to start (it crashed).
  if (model_.nq() != n_) return {StatusCode::kNotInitialized, Channel::kNone, -1};
  const Status s = observer_.reset(model_, data_, t, q, dq, tau);
  if (!s.ok()) return s;
  if (options_.drift && observer_.friction().offset != initial_offset_) {
    // Back to the configured offsets exactly, and the observer started from them as a fresh
    // estimator's (o + (o₀ − o) is not o₀ in floating point).
    observer_.set_offset(initial_offset_);
    (void)observer_.reset(model_, data_, t, q, dq, tau);  // the same inputs passed above
  }
  initialized_ = true;
  t_ = t;
  dq_prev_ = dq;
  have_dq_prev_ = true;
  ddq_filtered_.setZero();
  residual_filter_.reset();    // r = 0 at a reset
  velocity_filter_.reset(dq);  // at rest on the first q̇, which the observer started from
  detector_.reset();
  disagreement_on_ = false;
  have_disagreement_edge_ = false;
  spectrum_.size = 0;  // a reset run matches a fresh estimator's bit for bit
  spectrum_link_ = -1;
  isolation_ws_.forget_spectra();
  release_link_ = -1;
  if (options_.sensor.tare_samples > 0) {
    tare_.bias_S.setZero();
    tare_.request(options_.sensor.tare_samples);
  } else {
    tare_.request(0);  // a requested tare not finished: its samples were of the previous run
  }
  // Nothing of the previous run's estimate stays in result(): as a fresh estimator's after its
  // first reset (no estimate yet, r = 0).
  clear_output();
  out_.residual.setZero();
  if (options_.drift) {  // back to the configured bias, as a fresh estimator (offsets: above)
    out_.torque_offset = initial_offset_;
    if (options_.sensor.tare_samples == 0) tare_.bias_S = options_.sensor.bias_S;
    drift_quiet_since_ = t;
    drift_t_prev_ = t;
  }
  return s;
}

void ContactEstimator::apply_payload(int body, const Inertia* payload) noexcept {
  if (model_.nq() != n_) return;  // moved from: no model left
  if (payload_body_ >= 0) {
    const auto p = static_cast<std::size_t>(payload_body_);
    model_.bodies[p].inertia = nominal_inertia_[p];
  }
  payload_body_ = -1;
  if (payload != nullptr) {
    const auto b = static_cast<std::size_t>(body);
    model_.bodies[b].inertia = nominal_inertia_[b] + *payload;
    payload_body_ = body;
  }
  observer_.reanchor(model_, data_);  // the payload is taken as attached at the last sample
}

Status ContactEstimator::set_payload(int body, const Inertia& payload) noexcept {
  if (model_.nq() != n_) return {StatusCode::kNotInitialized, Channel::kNone, -1};
  if (body < 0 || body >= model_.num_bodies())
    return {StatusCode::kWrongSize, Channel::kNone, body};
  if (!finite_inertia(payload)) return {StatusCode::kNonFinite, Channel::kNone, body};
  apply_payload(body, &payload);
  return Status::success();
}

Status ContactEstimator::validate_sample(double t, const Eigen::Ref<const VectorX>& q,
                                         const Eigen::Ref<const VectorX>& dq,
                                         const Eigen::Ref<const VectorX>& tau,
                                         const Vector6& reading_S) const noexcept {
  // The estimator's own clock: update_with() advances it without the observer's.
  if (std::isfinite(t) && !(t - t_ >= kShortestTimeStep))
    return {StatusCode::kNonIncreasingTime, Channel::kTime, 0};
  if (Status s = observer_.validate(t, q, dq, tau); !s.ok()) return s;
  return check_reading(options_.sensor.type, reading_S);
}

void ContactEstimator::fail(double t, Status s) noexcept {
  // Outputs only: no state is touched, so the next good sample continues as if this one never came.
  // The declaration in force stays (the detector did not change): a monitor reading `contact`
  // sees no gap in a contact for a sample it could not use.
  const bool declared = initialized_ && detector_.result().contact;
  const int link = declared ? out_.link : -1;
  clear_output();
  out_.residual.setConstant(kNaN);
  out_.t = t;
  out_.status = s;
  out_.contact = declared;
  out_.link = link;
  if (declared) out_.flags = EstimateFlag::kContact;
}

Status ContactEstimator::update(const Sample& s) noexcept {
  const SensorType type = options_.sensor.type;
  const bool has_reading =
      type == SensorType::kNone || (s.has_force && (type == SensorType::kForce || s.has_moment));
  if (!has_reading) {
    fail(s.t, {StatusCode::kWrongSize, Channel::kBaseWrench, 0});  // the sensor needs a reading
    return out_.status;
  }
  return update(s.t, s.q, s.dq, s.tau, s.reading_S);
}

Status ContactEstimator::update(double t, const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau) noexcept {
  if (options_.sensor.type != SensorType::kNone) {
    fail(t, {StatusCode::kWrongSize, Channel::kBaseWrench, 0});  // the sensor needs a reading
    return out_.status;
  }
  return update(t, q, dq, tau, Vector6::Zero());
}

Status ContactEstimator::update(double t, const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau,
                                const Vector6& reading_S) noexcept {
  // A moved-from estimator has no model left (nq -1): it needs a reset as a new one would.
  if (!initialized_ || model_.nq() != n_) {
    fail(t, {StatusCode::kNotInitialized, Channel::kNone, -1});
    return out_.status;
  }
  if (Status s = validate_sample(t, q, dq, tau, reading_S); !s.ok()) {
    fail(t, s);
    return s;
  }
  const double dt = t - t_;
  ddq_supplied_ = false;
  // The momentum and its bias terms take q̇ through the velocity filter (validated above: its
  // state stays finite); friction, q̈̂'s differentiation and the thresholds the measured q̇.
  if (velocity_filter_.enabled()) {
    dq_filtered_ = dq;
    velocity_filter_.apply(dt, dq_filtered_);
  }
  const Eigen::Ref<const VectorX> dq_momentum =
      velocity_filter_.enabled() ? Eigen::Ref<const VectorX>(dq_filtered_) : dq;
  momentum_and_bias_terms_stage(q, dq_momentum);           // 1
  observer_.integrate(data_, t, q, dq_momentum, tau, dq);  // 2 (validated above)
  out_.status = acceleration_route(dt, dq, tau);           // 3
  ground_wrench(dq_momentum);                              // 4
  residual_filter_.apply(dt, tau_ext_);                    // τ̂_ext low-passed (no-op by default)
  dq_prev_ = dq;
  t_ = t;
  estimate(t, dq, reading_S);  // 5–9
  return out_.status;
}

// 1. In: q, q̇. Out (data_): poses X_WB and motion subspaces S of q, momentum,
// coriolis_transpose_dq, gravity_torque; with route (b) and a q̈̂ also the world-frame mass
// properties and the bias c(q, q̇) (data_.tau) with its ground wrench f_0(0)
// (data_.root_wrench_W), which the same pass gives; route (a) the mass properties for its RNEA;
// case E neither.
void ContactEstimator::momentum_and_bias_terms_stage(const Eigen::Ref<const VectorX>& q,
                                                     const Eigen::Ref<const VectorX>& dq) noexcept {
  if (!need_ddq_) {
    momentum_terms(model_, data_, q, dq);
  } else if (differentiation_) {
    momentum_terms(model_, data_, q, dq);
    world_mass_properties(model_, data_);
  } else {
    momentum_and_bias_terms(model_, data_, q, dq);
  }
}

// Backward difference of q̇ through a first-order low-pass (cutoff f_c), exact discretization
// for the actual Δt, into ddq_filtered_.
void ContactEstimator::differentiate_velocity(double dt,
                                              const Eigen::Ref<const VectorX>& dq) noexcept {
  const double a = std::exp(-2.0 * std::numbers::pi * options_.differentiation_cutoff * dt);
  for (int i = 0; i < n_; ++i) {
    const double raw = (dq[i] - dq_prev_[i]) / dt;
    ddq_filtered_[i] = a * ddq_filtered_[i] + (1.0 - a) * raw;
  }
}

// 3. In: Δt, q̇, τ, r and τ_f (observer), data_ of stage 1. Out: tau_eff_ = τ − τ_f, ddq_ = q̈̂
// (NaN when not needed or singular), data_.M with route (b); kSingular when B(q) cannot be
// factored.
Status ContactEstimator::acceleration_route(double dt, const Eigen::Ref<const VectorX>& dq,
                                            const Eigen::Ref<const VectorX>& tau) noexcept {
  tau_eff_ = tau - observer_.friction_torque();  // τ − τ_f
  if (differentiation_) {
    differentiate_velocity(dt, dq);  // (a) q̈̂
    ddq_ = ddq_filtered_;
    return Status::success();
  }
  if (!need_ddq_) {
    ddq_.setConstant(kNaN);
    return Status::success();
  }
  // With a base sensor the differentiated q̇ is kept too: the release falls back on it where the
  // sensor alone cannot tell the force (sensor_release.cpp).
  differentiate_velocity(dt, dq);
  // (b) q̈̂ = B⁻¹ (τ − τ_f + r − c(q, q̇)): forward dynamics with τ + r. The kinematics of q and
  // c = C q̇ + g (data_.tau) are already in data_ (stage 1).
  crba_no_kinematics(model_, data_);
  // The joint-space inertia the observer assumes, B(q) + δI (options.inertia_correction), so that
  // q̈̂ solves the same balance as the residual it comes from.
  if (inertia_corrected_) data_.M.diagonal() += observer_.inertia_correction();
  ddq_ = tau_eff_ + observer_.residual() - data_.tau;
  bool factored = false;
  if (n_ == 7) {
    factored = factor_and_solve_fixed<7>(data_.M, mass_ldlt_, ddq_);
  } else if (n_ == 6) {
    factored = factor_and_solve_fixed<6>(data_.M, mass_ldlt_, ddq_);
  } else if (n_ <= kInlineJoints) {
    mass_ldlt_ = data_.M;  // fixed capacity: no allocation
    factored = ldlt_in_place(mass_ldlt_);
    if (factored) ldlt_solve(mass_ldlt_, ddq_);
  } else {
    data_.mass_llt.compute(data_.M);
    factored = data_.mass_llt.info() == Eigen::Success;
    if (factored) data_.mass_llt.solveInPlace(ddq_);
  }
  if (factored) return Status::success();
  ddq_.setConstant(kNaN);
  return {StatusCode::kSingular, Channel::kAcceleration, -1};
}

// 4. In: q̇, q̈̂ (stage 3), data_ of stages 1 and 3. Out: data_.root_wrench_W = (f̃_g, ñ_g), the
// wrench the robot would discharge onto its base with this motion and no contact (when q̈̂ is
// valid); tau_ext_ = τ̂_ext of the route.
void ContactEstimator::ground_wrench(const Eigen::Ref<const VectorX>& dq) noexcept {
  if (differentiation_) {
    // One RNEA pass with W_ext = 0 and q̈ = q̈̂: τ_tot in data_.tau and the ground wrench.
    if (out_.status.ok()) rnea_no_kinematics(model_, data_, dq, ddq_);
    tau_ext_ = data_.tau - tau_eff_;  // (a) τ̂_ext = RNEA(q, q̇, q̈̂) − (τ − τ_f)
    return;
  }
  root_wrench_dddq_valid_ = false;
  if (need_ddq_ && out_.status.ok()) {
    // f_0 is affine in q̈: f_0(q̈̂) = f_0(0) + Σ_j Ic_j S_j q̈̂_j, Ic_j the composite inertia of
    // the subtree of j that the CRBA of stage 3 left in data_ (about the world origin): with
    // mass m, first moment h and inertia I_O, Ic_j S_j = (m s_v − h × s_ω, h × s_v + I_O s_ω).
    // Saves a second RNEA pass; the columns are kept for the release force (stage 5b).
    Vector6 f0 = data_.root_wrench_W;
    for (int j = 1; j < model_.num_bodies(); ++j) {
      const auto js = static_cast<std::size_t>(j);
      const Vector6& s = data_.S[js];
      const double m = data_.composite_mass[js];
      const Vector3& h = data_.composite_first_moment[js];
      auto column = root_wrench_dddq_.col(j - 1);
      column.head<3>() = m * s.head<3>() - h.cross(s.tail<3>());
      column.tail<3>() = h.cross(s.head<3>()) + data_.composite_inertia_O[js] * s.tail<3>();
      const double a = ddq_[j - 1];
      f0.head<3>() += a * column.head<3>();
      f0.tail<3>() += a * column.tail<3>();
    }
    data_.root_wrench_W = f0;
    root_wrench_dddq_valid_ = true;
  }
  tau_ext_ = observer_.residual();  // (b) τ̂_ext = r
}

Status ContactEstimator::update_with(double t, const Eigen::Ref<const VectorX>& q,
                                     const Eigen::Ref<const VectorX>& dq,
                                     const Eigen::Ref<const VectorX>& ddq,
                                     const Eigen::Ref<const VectorX>& tau_ext,
                                     const Eigen::Ref<const VectorX>& tau,
                                     const Vector6& reading_S) noexcept {
  Status s = Status::success();
  if (model_.nq() != n_) {  // moved from: no model left
    s = {StatusCode::kNotInitialized, Channel::kNone, -1};
  } else if (!usable_time(t)) {
    s = {StatusCode::kNonFinite, Channel::kTime, 0};
  } else if (initialized_ && !(t - t_ >= kShortestTimeStep)) {
    s = {StatusCode::kNonIncreasingTime, Channel::kTime, 0};
  }
  if (s.ok()) s = check_vector(q, n_, Channel::kPosition);
  if (s.ok()) s = check_vector(dq, n_, Channel::kVelocity);
  if (s.ok()) s = check_vector(ddq, n_, Channel::kAcceleration);
  if (s.ok()) s = check_vector(tau_ext, n_, Channel::kTorque);
  if (s.ok()) s = check_vector(tau, n_, Channel::kTorque);
  if (s.ok()) s = check_reading(options_.sensor.type, reading_S);
  if (!s.ok()) {
    fail(t, s);
    return s;
  }
  forward_kinematics(model_, data_, q);
  ddq_ = ddq;
  ddq_supplied_ = true;
  root_wrench_dddq_valid_ = false;
  tau_ext_ = tau_ext;
  if (!initialized_) residual_filter_.reset(tau_ext_);  // a start at rest on the first value
  residual_filter_.apply(initialized_ ? t - t_ : 0.0, tau_ext_);
  rnea_no_kinematics(model_, data_, dq, ddq_);
  initialized_ = true;
  t_ = t;
  out_.status = Status::success();
  estimate(t, dq, reading_S);
  return out_.status;
}

void ContactEstimator::clear_output() noexcept {
  VectorX residual = std::move(out_.residual);
  VectorX offset = std::move(out_.torque_offset);
  out_ = ContactEstimate{};
  out_.residual = std::move(residual);
  out_.torque_offset = std::move(offset);
}

void ContactEstimator::begin_output(double t) noexcept {
  const Status status = out_.status;
  clear_output();
  out_.status = status;
  out_.t = t;
  out_.residual = tau_ext_;
}

// Stages 5–9 on τ̂_ext, q̇ (thresholds that follow it) and data_ (poses, ground wrench). Out: out_.
void ContactEstimator::estimate(double t, const Eigen::Ref<const VectorX>& dq,
                                const Vector6& reading_S) noexcept {
  begin_output(t);
  std::uint32_t flags = 0;
  const bool has_sensor = options_.sensor.type != SensorType::kNone && out_.status.ok();
  BaseWrench base;
  base.force_W.setConstant(kNaN);
  base.dn_W.setConstant(kNaN);
  if (has_sensor) base = base_sensor_reading(reading_S, flags);  // 5
  // 6. Detection.
  const double base_force = has_sensor && !base.taring ? base.force_W.norm() : kNaN;
  const ReleaseForces release = has_sensor && !base.taring && release_link_ >= 0
                                    ? sensor_release_forces(base)
                                    : ReleaseForces{};
  // Thresholds that follow |q̇| and |τ_dyn| (no-op when constant). τ_dyn = τ − τ_f − g + τ̂_ext
  // needs stage 1's g: not after update_with, whose caller gave q̈̂ (there only |q̇|).
  if (detector_.inertia_dependent() && !ddq_supplied_) {
    dynamic_torque_ = tau_eff_ - data_.gravity_torque + tau_ext_;
    detector_.set_motion(dq, dynamic_torque_);
  } else {
    detector_.set_motion(dq);
  }
  const DetectionResult& det =
      detector_.update(t, tau_ext_, base_force, release.either, release.measured);
  out_.contact = det.contact;
  flags |= detection_flags(det);
  if (options_.drift) track_drift(t, det, base);
  // 7. Isolation.
  geometric_link_ = -1;
  int link = isolate(det, options_.contact.model, options_.contact.link, flags);
  if (link >= 0 && isolation_rule_ == IsolationRule::kGeometry &&
      options_.contact.model == ContactModel::kPureForce && out_.status.ok()) {
    link = geometric_isolation(link, base, flags);
  }
  if (has_sensor) {
    out_.force_W = base.force_W;
    flags |= EstimateFlag::kForce;
  }
  release_link_ = det.contact && link >= 0 ? link : -1;
  if (link < 0) {
    if (has_sensor && noise_.configured) sensor_force_uncertainty();  // 10
    out_.flags = flags;
    disagreement_on_ = false;
    have_disagreement_edge_ = false;
    return;
  }
  out_.link = link;
  static const WrenchFit kNoFit;  // nothing estimated on a bad q̈̂
  const WrenchFit& fit = out_.status.ok() ? table_one_case(link, base, flags) : kNoFit;  // 8
  contact_point(link, fit, det.contact, flags);                                          // 9
  consistency(t, link, det.contact, fit, flags);
  if (noise_.configured) uncertainty(link, fit, flags);  // 10
  release_point_L_ = out_.point_L.allFinite() ? out_.point_L : Vector3::Zero();
  out_.flags = flags;
}

// Drift tracking (after detection): while no contact is declared, pending or raw, and one
// settling time after the last such sample, the offsets o_i follow −r_i (r ≈ τ_ext + o_true − o)
// and the bias follows F̂_ext and n_m − ñ_g in S, as first-order filters of time constant T
// with each step bounded by its rate × Δt. In: det, base (stage 5), observer_.residual().
// Out: the observer's offsets, tare_.bias_S, out_.torque_offset, out_.sensor_bias_S.
void ContactEstimator::track_drift(double t, const DetectionResult& det,
                                   const BaseWrench& base) noexcept {
  const DriftOptions& d = *options_.drift;
  const double dt = t - drift_t_prev_;
  drift_t_prev_ = t;
  const bool busy = det.contact || det.pending || det.raw || base.taring || !out_.status.ok();
  if (busy) drift_quiet_since_ = t;
  if (!busy && dt > 0.0 && t - drift_quiet_since_ >= settle_time_) {
    const double a = dt / (d.time_constant + dt);  // backward-Euler first-order filter
    const double max_torque = d.max_torque_rate * dt;
    drift_delta_ = (-a * observer_.residual()).cwiseMax(-max_torque).cwiseMin(max_torque);
    observer_.shift_offset(drift_delta_);
    if (options_.sensor.type != SensorType::kNone) {
      const Matrix3& R_WS = options_.sensor.X_WS.rotation;
      const double max_force = d.max_force_rate * dt;
      const Vector3 force_S = R_WS.transpose() * base.force_W;
      tare_.bias_S.head<3>() += (a * force_S).cwiseMax(-max_force).cwiseMin(max_force);
      if (options_.sensor.type == SensorType::kForceTorque) {
        const double max_moment = d.max_moment_rate * dt;
        const Vector3 moment_S = R_WS.transpose() * base.dn_W;
        tare_.bias_S.tail<3>() += (a * moment_S).cwiseMax(-max_moment).cwiseMin(max_moment);
      }
    }
  }
  out_.torque_offset = observer_.friction().offset;
  if (options_.sensor.type != SensorType::kNone) out_.sensor_bias_S = tare_.bias_S;
  if (options_.sensor.type == SensorType::kForce) out_.sensor_bias_S.tail<3>().setConstant(kNaN);
}

// 5. In: the reading [f; n] in S, data_.root_wrench_W of stage 4. Out: F̂_ext (11) and
// n_m − ñ_g (13) in W about O_s; the tare advanced (kTaring in `flags` while it runs).
BaseWrench ContactEstimator::base_sensor_reading(const Vector6& reading_S,
                                                 std::uint32_t& flags) noexcept {
  const Pose& X_WS = options_.sensor.X_WS;
  // What the robot would discharge with this motion and no contact (f̃_g, ñ_g), world, about O_s.
  const Vector6 predicted_W = sensor_reading_world(data_, X_WS.translation);
  const BaseWrench base = base_wrench(options_.sensor.type, X_WS, reading_S, predicted_W, tare_);
  if (base.taring) flags |= EstimateFlag::kTaring;
  return base;
}

// 7b. In: l_r of the paper's rule, the base wrench, τ̂_ext, data_ (poses). Out: the link chosen
// among l_r … n by the residual and the shapes (isolation.hpp), out_.link_candidates, and
// kAmbiguous or kResidualIsolation in `flags`.
int ContactEstimator::geometric_isolation(int residual_link, const BaseWrench& base,
                                          std::uint32_t& flags) noexcept {
  IsolationInputs in;
  in.sensor = options_.sensor.type;
  in.residual_link = residual_link;
  in.tau_ext = &tau_ext_;
  in.tau_min = &detector_.thresholds();
  in.base = &base;
  in.p_WS = options_.sensor.X_WS.translation;
  // The candidate that stage 8 solved last starts from stage 8's warm start: if it is chosen
  // again, its fit is then the very solve stage 8 would make (table_one_case takes it over).
  if (spectrum_link_ >= 0)
    isolation_ws_.guess[static_cast<std::size_t>(spectrum_link_)] = spectrum_;
  const IsolationResult r = isolate_on_geometry(model_, data_, geometry_, in, options_.isolation,
                                                options_.solver, isolation_ws_);
  if (!r.decided) {
    flags |= EstimateFlag::kResidualIsolation;
    return residual_link;
  }
  geometric_link_ = r.link;
  out_.link_candidates = r.candidates & ~(std::uint64_t{1} << r.link);
  if (r.ambiguous) flags |= EstimateFlag::kAmbiguous;
  return r.link;
}

// 8. In: the isolated link, the base wrench of stage 5, data_ (poses). Out: J_ = J_l of O_l,
// the fit of the sensor's Table I case; out_.condition_number, out_.force_W (case E) and the
// kForce, kIllConditioned, kUnobservable flags.
const WrenchFit& ContactEstimator::table_one_case(int link, const BaseWrench& base,
                                                  std::uint32_t& flags) noexcept {
  const Vector3& O_l = data_.X_WB[static_cast<std::size_t>(link)].translation;
  // J_l of O_l: [J_v,l; J_ω,l], zero beyond l. Geometric isolation computed it when the link was
  // its last candidate: the same bits, taken over by a swap of the buffers.
  if (link == geometric_link_ && isolation_ws_.jacobian_link == link) {
    J_.swap(isolation_ws_.J);
    isolation_ws_.jacobian_link = -1;
  } else {
    point_jacobian(model_, data_, link, O_l, J_);
  }
  // Geometric isolation made this very solve already (same J_l, τ̂ and warm start): take it over.
  // A link chosen along another candidate's line takes that candidate's fit (isolation.hpp).
  const auto l = static_cast<std::size_t>(link);
  const bool borrowed = link == geometric_link_ && isolation_ws_.tested[l].borrowed;
  const bool solved = link == geometric_link_ && (link == spectrum_link_ || borrowed);
  WrenchFit& fit = solved ? isolation_ws_.tested[l].fit : fit_;
  if (!solved) {
    fit_wrench_case(fit, options_.sensor.type, J_, link, tau_ext_, base, O_l,
                    options_.sensor.X_WS.translation, options_.solver, b_, spectrum_);
  }
  if (solved && !borrowed) spectrum_ = isolation_ws_.guess[l];
  spectrum_link_ = borrowed ? -1 : link;  // no warm start of this link's own solve
  if (options_.sensor.type != SensorType::kForceTorque) out_.condition_number = fit.condition;
  if (fit.fitted_force) {
    out_.force_W = fit.force_W;
    flags |= EstimateFlag::kForce;
  }
  if (fit.damped) flags |= EstimateFlag::kIllConditioned;
  if (!fit.ok) flags |= EstimateFlag::kUnobservable;
  // A short chain (fewer than 6 joints: rank J_l < 6 whatever q) cannot tell F from M at all;
  // the force alone is its answer. A longer one at a singularity keeps case E's observable
  // part: there a pure moment can pass for a force at a short lever, undetectably.
  if (!fit.ok && options_.contact.model == ContactModel::kKnownPoint &&
      options_.sensor.type == SensorType::kNone && link < 6)
    known_point_force(link, fit, flags);
  if (fit.partial) {
    flags |= EstimateFlag::kPartial;
    out_.observable_basis_W = fit.basis_W;
    out_.observable_rank = fit.rank;
  }
  return fit;
}

// 8b. Known point, no sensor, rank J_l < 6 (a short chain): the force alone at p (M_ext taken
// as 0), J_v,pᵀ F = τ̂, minimum-norm on its observable subspace (docs/estimator.md#partial-
// observability). Out: fit.force_W, its basis, out_.force_W and kForce.
void ContactEstimator::known_point_force(int link, WrenchFit& fit, std::uint32_t& flags) noexcept {
  const Pose& X_WL = data_.X_WB[static_cast<std::size_t>(link)];
  point_jacobian(model_, data_, link, X_WL.act(options_.contact.point_L), J_);
  Vector3 x;
  Matrix3 basis;
  double damping = 0.0;
  const int rank =
      min_norm_solve<3>(J_.topRows<3>(), link, tau_ext_, options_.solver, x, basis, damping);
  if (rank == 0) return;
  // The force at the point replaces case E's wrench: its own solve says whether it was damped.
  fit.damping = damping;
  fit.damped = damping > 0.0;
  if (fit.damped) {
    flags |= EstimateFlag::kIllConditioned;
  } else {
    flags &= ~EstimateFlag::kIllConditioned;
  }
  fit.force_W = x;
  fit.partial = true;
  fit.point_force = true;
  fit.rank = rank;
  fit.basis_W.setZero();
  fit.basis_W.topLeftCorner<3, 3>() = basis;
  out_.force_W = x;
  flags |= EstimateFlag::kForce;
}

// 9. In: the link, the fit, the declared contact, data_ (X_WL). Out: with a known point, the
// point and M̂_ext (15); else, for a declared contact, the line of action (19)–(21) and its
// entry on the link's surface (localization.hpp).
void ContactEstimator::contact_point(int link, const WrenchFit& fit, bool contact,
                                     std::uint32_t& flags) noexcept {
  const Pose& X_WL = data_.X_WB[static_cast<std::size_t>(link)];
  const Vector3& O_l = X_WL.translation;
  if (options_.contact.model == ContactModel::kKnownPoint) {
    const Vector3 p_W = X_WL.act(options_.contact.point_L);
    out_.point_W = p_W;
    out_.point_L = options_.contact.point_L;
    flags |= EstimateFlag::kKnownPoint;
    if (fit.ok) {
      out_.moment_W = known_point_moment(fit, p_W, O_l);
      flags |= EstimateFlag::kMoment;
    } else if (fit.partial && options_.sensor.type == SensorType::kForce) {
      // Case D's observable part: M = P (M̄ − r_{l,p} × F), P the projector on the observable
      // moment directions (the minimum-norm M, not the minimum-norm M̄ shifted).
      const auto B = fit.basis_W.block<3, 3>(3, 3);
      out_.moment_W = fit.moment_O - B * (B.transpose() * (p_W - O_l).cross(fit.force_W));
      flags |= EstimateFlag::kMoment;
    }
  } else if (fit.ok && contact) {
    const TestedCandidate& c = isolation_ws_.tested[static_cast<std::size_t>(link)];
    const bool borrowed = link == geometric_link_ && c.borrowed;
    if (borrowed) {  // the line isolation chose the link by (bit for bit)
      out_.line_point_W = c.line_point_W;
      out_.line_direction_W = c.line_direction_W;
    }
    if (borrowed || line_of_action(fit, O_l, out_.line_point_W, out_.line_direction_W)) {
      flags |= EstimateFlag::kLineOfAction;
      // Geometric isolation met this very line with this link's shapes already: take its entry.
      const bool known =
          link == geometric_link_ && c.is_line(out_.line_point_W, out_.line_direction_W);
      locate_on_surface(geometry_, link, X_WL, out_, flags, surface_normal_W_,
                        known ? &c.entry : nullptr);
    }
  }
}

// Consistency of the base wrench (or the fitted wrench) with the residual (wrench_cases.hpp).
// Not judged while damped (the fit is biased on purpose), and only once it has lasted longer
// than the residual's transient. Out: kDisagreement in `flags`.
void ContactEstimator::consistency(double t, int link, bool contact, const WrenchFit& fit,
                                   std::uint32_t& flags) noexcept {
  const bool inconsistent =
      contact && fit.ok && !fit.damped && link > 0 &&
      contradicts_residual(J_, fit, tau_ext_, detector_.thresholds(), tau_pred_);
  if (inconsistent) {
    if (!have_disagreement_edge_) {
      have_disagreement_edge_ = true;
      disagreement_edge_ = t;
    }
    if (t - disagreement_edge_ >= settle_time_ - kTimeSlack) disagreement_on_ = true;
  } else {
    have_disagreement_edge_ = false;
    disagreement_on_ = false;
  }
  if (disagreement_on_) flags |= EstimateFlag::kDisagreement;
}

}  // namespace extwrench
