#include "extwrench/estimation/contact_estimator.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/geometry/ray.hpp"

namespace extwrench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// Time stamps are sums of floating steps: a duration reached up to this slack counts as reached.
constexpr double kTimeSlack = 1e-9;  // [s]
// A residual / filter transient is over after this many time constants (e^{-5} < 1 %).
constexpr double kSettleTimeConstants = 5.0;

struct DlsInfo {
  bool rank_ok = false;  ///< σ_min > rank_tolerance · σ_max
  bool damped = false;   ///< σ_min < σ_max / max_condition: damping active
  double condition = kNaN;
};

/// A = L D Lᵀ in place (unit lower L below the diagonal, 1/D on it; the upper triangle is not
/// read): no square roots, and the solves multiply by the stored inverse pivots, which keeps
/// divisions off their dependency chains. False when A is not numerically positive definite.
/// Matrices of fixed capacity only (the fixed-size J Jᵀ, B(q) in mass_ldlt_): the pivots then
/// fit on the stack, and nothing is allocated.
template <typename Matrix>
bool ldlt_in_place(Matrix& A) noexcept {
  static_assert(Matrix::MaxRowsAtCompileTime != Eigen::Dynamic, "needs a fixed capacity");
  const int n = static_cast<int>(A.rows());
  double d[Matrix::MaxRowsAtCompileTime];
  for (int j = 0; j < n; ++j) {
    double dj = A(j, j);
    for (int k = 0; k < j; ++k) dj -= A(j, k) * A(j, k) * d[k];
    if (!(dj > 0.0)) return false;
    d[j] = dj;
    const double inv = 1.0 / dj;
    A(j, j) = inv;
    for (int i = j + 1; i < n; ++i) {
      double sum = A(i, j);
      for (int k = 0; k < j; ++k) sum -= A(i, k) * A(j, k) * d[k];
      A(i, j) = sum * inv;
    }
  }
  return true;
}

/// x ← A⁻¹ x with the factor of ldlt_in_place.
template <typename Matrix, typename Vector>
void ldlt_solve(const Matrix& LD, Vector& x) noexcept {
  const int n = static_cast<int>(LD.rows());
  for (int i = 1; i < n; ++i) {
    for (int k = 0; k < i; ++k) x[i] -= LD(i, k) * x[k];
  }
  for (int i = 0; i < n; ++i) x[i] *= LD(i, i);
  for (int i = n - 2; i >= 0; --i) {
    for (int k = i + 1; k < n; ++k) x[i] -= LD(k, i) * x[k];
  }
}

// Power / inverse iteration on J Jᵀ from the last sample's extreme eigenvectors: accepted once
// the relative residual ‖A v − ρ v‖/ρ is below kSpectrumTolerance for both ends, which bounds
// the eigenvalue error by ~tol² ρ²/gap (~1e-6 relative or better); else the exact path.
constexpr double kSpectrumTolerance = 1e-3;
constexpr int kSpectrumIterations = 4;

/// Solves Jᵀ x = b in the damped least-squares sense, J: R×n of which only the first `cols`
/// columns (the joints up to the contact link) can be non-zero. x = (J Jᵀ + μ² I)⁻¹ J b with
/// the damping law of the header, by an LDLᵀ factorisation (fixed size: no allocation). σ_min and
/// σ_max come from the extreme eigenvalues of A = J Jᵀ: J moves little between samples, so a few
/// power (λ_max) and inverse (λ_min, with the LDLᵀ factor) iterations from the previous
/// sample's eigenvectors (`guess`, `guess_size` = R when valid) usually suffice; otherwise (first
/// sample, a change of link, fast motion near a singularity) a full symmetric eigensolver gives
/// them exactly and seeds the next sample. The normal equations square κ: with κ ≤ 1e3 the
/// relative error stays ~1e-10.
template <int R, typename Derived>
DlsInfo damped_solve(const Eigen::MatrixBase<Derived>& J, int cols, const VectorX& b,
                     const SolverOptions& opt, Eigen::Matrix<double, R, 1>& x, Vector6& guess_min,
                     Vector6& guess_max, int& guess_size) noexcept {
  using MatR = Eigen::Matrix<double, R, R>;
  using VecR = Eigen::Matrix<double, R, 1>;
  MatR A;
  A.noalias() = J.leftCols(cols) * J.leftCols(cols).transpose();
  x.noalias() = J.leftCols(cols) * b.head(cols);
  MatR L = A;
  const bool factored = ldlt_in_place(L);
  double l_min = 0.0;
  double l_max = 0.0;
  bool estimated = false;
  if (factored && guess_size == R) {
    VecR v_max = guess_max.head<R>();
    VecR v_min = guess_min.head<R>();
    for (int it = 0; it < kSpectrumIterations && !estimated; ++it) {
      const VecR u = A * v_max;  // power step: λ_max ≈ ρ = vᵀ A v
      const double rho = v_max.dot(u);
      const double res_max = (u - rho * v_max).norm();
      v_max = u / u.norm();
      VecR y = v_min;  // inverse step: 1/λ_min ≈ μ = vᵀ A⁻¹ v
      ldlt_solve(L, y);
      const double mu = v_min.dot(y);
      const double res_min = (y - mu * v_min).norm();
      v_min = y / y.norm();
      l_max = rho;
      l_min = 1.0 / mu;
      estimated = res_max <= kSpectrumTolerance * rho && res_min <= kSpectrumTolerance * mu;
    }
    guess_max.head<R>() = v_max;
    guess_min.head<R>() = v_min;
  }
  if (!estimated) {
    const Eigen::SelfAdjointEigenSolver<MatR> eig(A);
    l_min = eig.eigenvalues()[0];
    l_max = eig.eigenvalues()[R - 1];
    guess_min.head<R>() = eig.eigenvectors().col(0);
    guess_max.head<R>() = eig.eigenvectors().col(R - 1);
    guess_size = R;
  }
  const double s_max = std::sqrt(std::max(l_max, 0.0));
  const double s_min = std::sqrt(std::max(l_min, 0.0));
  DlsInfo info;
  info.condition = s_min > 0.0 ? s_max / s_min : kInf;
  info.rank_ok = s_max > 0.0 && s_min > opt.rank_tolerance * s_max;
  const double eps = s_max / opt.max_condition;  // ε = σ_max / κ_max
  const double mu2 = s_min < eps ? eps * eps - s_min * s_min : 0.0;
  info.damped = mu2 > 0.0;
  bool solved = false;
  if (info.rank_ok) {
    // rank_ok ⇒ σ_min > 0 ⇒ J Jᵀ + μ² I is positive definite (round-off checked).
    if (mu2 == 0.0 && factored) {
      solved = true;
    } else {
      L = A;
      L.diagonal().array() += mu2;
      solved = ldlt_in_place(L);
    }
    if (solved) ldlt_solve(L, x);
  }
  if (!solved) {
    info.rank_ok = false;
    x.setConstant(kNaN);  // unused by the callers: the wrench is unobservable
  }
  return info;
}

Status check_vector(const Eigen::Ref<const VectorX>& v, int n, Channel channel) noexcept {
  if (v.size() != n) return {StatusCode::kWrongSize, channel, static_cast<int>(v.size())};
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return {StatusCode::kNonFinite, channel, i};
  }
  return Status::success();
}

const Model& checked_model(const Model& model, const EstimatorOptions& o) {
  const std::string where = "estimator for robot '" + model.name + "'";
  if (!model.is_serial_chain()) {
    throw Error(where + ": the model is not a serial chain; isolation by joint index needs one");
  }
  if (o.contact.model == ContactModel::kKnownPoint) {
    if (o.contact.link < 0 || o.contact.link >= model.num_bodies()) {
      throw Error(where + ": contact.link: body index " + std::to_string(o.contact.link) +
                  " is not in [0, " + std::to_string(model.num_bodies() - 1) + "]");
    }
    if (!o.contact.point.allFinite())
      throw Error(where + ": contact.point: expected finite values");
  }
  const Pose& X = o.sensor.pose;
  if (!X.translation.allFinite() || !X.rotation.allFinite() ||
      !(X.rotation * X.rotation.transpose()).isIdentity(1e-9) || X.rotation.determinant() < 0) {
    throw Error(where + ": sensor.pose: expected a finite rigid transform");
  }
  if (o.sensor.tare_samples < 0) throw Error(where + ": sensor.tare: expected a sample count >= 0");
  if (!(o.differentiation_cutoff > 0.0) || !std::isfinite(o.differentiation_cutoff)) {
    throw Error(where + ": acceleration cutoff: expected a finite value > 0 [Hz]");
  }
  if (!(o.solver.max_condition > 1.0) || !std::isfinite(o.solver.max_condition)) {
    throw Error(where + ": solver.max_condition: expected a finite value > 1");
  }
  if (!(o.solver.rank_tolerance > 0.0 && o.solver.rank_tolerance < 1.0)) {
    throw Error(where + ": solver.rank_tolerance: expected a value in (0, 1)");
  }
  if (o.payload && (o.payload->body < 0 || o.payload->body >= model.num_bodies())) {
    throw Error(where + ": payload.link: body index " + std::to_string(o.payload->body) +
                " is not in the model");
  }
  return model;
}

}  // namespace

ContactEstimator::ContactEstimator(Model model, GeometryModel geometry, EstimatorOptions options)
    : options_(std::move(options)),
      geometry_(std::move(geometry)),
      observer_((checked_model(model, options_), std::move(model)), options_.observer_gain),
      detector_(options_.detection, observer_.nq()),
      n_(observer_.nq()) {
  const Model& m = observer_.model();
  if (geometry_.body_shapes.empty())
    geometry_.body_shapes.resize(static_cast<std::size_t>(m.num_bodies()));
  if (static_cast<int>(geometry_.body_shapes.size()) != m.num_bodies()) {
    throw Error("estimator for robot '" + m.name + "': the collision geometry has " +
                std::to_string(geometry_.body_shapes.size()) + " bodies, the model " +
                std::to_string(m.num_bodies()));
  }
  if (options_.friction) observer_.set_friction(*options_.friction);
  if (options_.payload) {
    const Status s = observer_.set_payload(options_.payload->body, options_.payload->inertia);
    if (!s.ok())
      throw Error("estimator for robot '" + m.name +
                  "': payload: non-finite or negative mass properties");
  }
  const double slowest = options_.acceleration == AccelerationRoute::kResidual
                             ? 1.0 / observer_.gains().minCoeff()
                             : 1.0 / (2.0 * std::numbers::pi * options_.differentiation_cutoff);
  settle_time_ = std::max(kSettleTimeConstants * slowest, options_.detection.min_duration);
  dq_prev_ = VectorX::Zero(n_);
  ddq_filtered_ = VectorX::Zero(n_);
  ddq_ = VectorX::Constant(n_, kNaN);
  tau_ext_ = VectorX::Zero(n_);
  b_ = VectorX::Zero(n_);
  tau_pred_ = VectorX::Zero(n_);
  tau_eff_ = VectorX::Zero(n_);
  J_ = Matrix6X::Zero(6, n_);
  out_.residual = VectorX::Zero(n_);
}

Status ContactEstimator::reset(double t, const Eigen::Ref<const VectorX>& q,
                               const Eigen::Ref<const VectorX>& dq,
                               const Eigen::Ref<const VectorX>& tau) noexcept {
  const Status s = observer_.reset(t, q, dq, tau);
  if (!s.ok()) return s;
  initialized_ = true;
  t_ = t;
  dq_prev_ = dq;
  have_dq_prev_ = true;
  ddq_filtered_.setZero();
  detector_.reset();
  disagreement_on_ = false;
  have_disagreement_edge_ = false;
  spectrum_size_ = 0;  // a reset run matches a fresh estimator's bit for bit
  if (options_.sensor.tare_samples > 0) {
    bias_S_.setZero();
    request_tare(options_.sensor.tare_samples);
  }
  out_.residual.setZero();
  return s;
}

void ContactEstimator::request_tare(int samples) noexcept {
  tare_target_ = samples > 0 ? samples : 0;
  tare_count_ = 0;
  tare_sum_.setZero();
}

Status ContactEstimator::set_payload(int body, const Inertia& payload) noexcept {
  return observer_.set_payload(body, payload);
}

Status ContactEstimator::validate_reading(const Vector6& reading_S) const noexcept {
  const int count = options_.sensor.type == SensorType::kForceTorque ? 6
                    : options_.sensor.type == SensorType::kForce     ? 3
                                                                     : 0;
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(reading_S[i])) return {StatusCode::kNonFinite, Channel::kBaseWrench, i};
  }
  return Status::success();
}

Status ContactEstimator::validate_common(double t, const Eigen::Ref<const VectorX>& q,
                                         const Eigen::Ref<const VectorX>& dq,
                                         const Eigen::Ref<const VectorX>& tau,
                                         const Vector6& reading_S) const noexcept {
  if (Status s = observer_.validate(t, q, dq, tau); !s.ok()) return s;
  return validate_reading(reading_S);
}

void ContactEstimator::fail(double t, Status s) noexcept {
  // Outputs only: no state is touched, so the next good sample continues as if this one never came.
  VectorX residual = std::move(out_.residual);  // keeps the buffer (no allocation)
  out_ = ContactEstimate{};
  out_.residual = std::move(residual);
  out_.residual.setConstant(kNaN);
  out_.t = t;
  out_.status = s;
}

Status ContactEstimator::update(double t, const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau) noexcept {
  if (options_.sensor.type != SensorType::kNone) {
    fail(t, {StatusCode::kWrongSize, Channel::kBaseWrench,
             0});  // a sensor is configured: reading needed
    return out_.status;
  }
  return update(t, q, dq, tau, Vector6::Zero());
}

Status ContactEstimator::update(double t, const Eigen::Ref<const VectorX>& q,
                                const Eigen::Ref<const VectorX>& dq,
                                const Eigen::Ref<const VectorX>& tau,
                                const Vector6& reading_S) noexcept {
  if (!initialized_) {
    fail(t, {StatusCode::kNotInitialized, Channel::kNone, -1});
    return out_.status;
  }
  if (Status s = validate_common(t, q, dq, tau, reading_S); !s.ok()) {
    fail(t, s);
    return s;
  }
  const double dt = t - t_;
  const bool need_ddq = options_.sensor.type != SensorType::kNone ||
                        options_.acceleration == AccelerationRoute::kDifferentiation;
  const bool differentiation = options_.acceleration == AccelerationRoute::kDifferentiation;
  // The observer's pass computes the poses and the momentum terms; route (b) also needs the
  // world-frame mass properties (CRBA) and the bias c(q, q̇) with its ground wrench, which the
  // same pass can give; route (a) needs the mass properties for its RNEA; case E neither.
  using Extras = MomentumObserver::Extras;
  const Extras extras = !need_ddq         ? Extras::kNone
                        : differentiation ? Extras::kWorldInertias
                                          : Extras::kWorldInertiasAndBias;
  observer_.advance(t, q, dq, tau, extras);  // validated above
  Data& data = observer_.workspace();
  const Model& model = observer_.model();
  out_.status = Status::success();
  tau_eff_ = tau - observer_.friction_torque();  // τ − τ_f
  if (options_.acceleration == AccelerationRoute::kDifferentiation) {
    // (a) q̈̂: backward difference of q̇ through a first-order low-pass (cutoff f_c), exact
    // discretization for the actual Δt.
    const double a = std::exp(-2.0 * std::numbers::pi * options_.differentiation_cutoff * dt);
    for (int i = 0; i < n_; ++i) {
      const double raw = (dq[i] - dq_prev_[i]) / dt;
      ddq_filtered_[i] = a * ddq_filtered_[i] + (1.0 - a) * raw;
    }
    ddq_ = ddq_filtered_;
  } else if (need_ddq) {
    // (b) q̈̂ = B⁻¹ (τ − τ_f + r − c(q, q̇)): forward dynamics with τ + r. The kinematics of q,
    // c = C q̇ + g (data.tau) and its ground wrench f_0(0) are already in `data` (observer pass).
    crba_no_kinematics(model, data);
    ddq_ = tau_eff_ + observer_.residual() - data.tau;
    bool factored = false;
    if (n_ <= kInlineJoints) {
      mass_ldlt_ = data.M;  // fixed capacity: no allocation
      factored = ldlt_in_place(mass_ldlt_);
      if (factored) ldlt_solve(mass_ldlt_, ddq_);
    } else {
      data.mass_llt.compute(data.M);
      factored = data.mass_llt.info() == Eigen::Success;
      if (factored) data.mass_llt.solveInPlace(ddq_);
    }
    if (!factored) {
      out_.status = {StatusCode::kSingular, Channel::kAcceleration, -1};
      ddq_.setConstant(kNaN);
    } else {
      // The no-contact ground wrench (f̃_g, ñ_g) is affine in q̈: f_0(q̈̂) = f_0(0) + Σ_j Ic_j S_j q̈̂_j,
      // Ic_j the composite inertia of the subtree of j that the CRBA just left in `data`
      // (about the world origin). Saves a second RNEA pass.
      Vector6 f0 = data.root_wrench_W;
      for (int j = 1; j < model.num_bodies(); ++j) {
        const auto js = static_cast<std::size_t>(j);
        const Vector6& s = data.S[js];
        const double m = data.composite_mass[js];
        const Vector3& h = data.composite_first_moment[js];
        const double a = ddq_[j - 1];
        f0.head<3>() += a * (m * s.head<3>() - h.cross(s.tail<3>()));
        f0.tail<3>() += a * (h.cross(s.head<3>()) + data.composite_inertia_O[js] * s.tail<3>());
      }
      data.root_wrench_W = f0;
    }
  } else {
    ddq_.setConstant(kNaN);
  }
  if (options_.acceleration == AccelerationRoute::kDifferentiation && out_.status.ok()) {
    // One RNEA pass with W_ext = 0 and q̈ = q̈̂: τ_tot in data.tau and the no-contact ground
    // wrench (f̃_g, ñ_g) in data.root_wrench_W.
    rnea_no_kinematics(model, data, dq, ddq_);
  }
  if (options_.acceleration == AccelerationRoute::kDifferentiation) {
    tau_ext_ = data.tau - tau_eff_;  // (a) τ̂_ext = RNEA(q, q̇, q̈̂) − (τ − τ_f)
  } else {
    tau_ext_ = observer_.residual();  // (b) τ̂_ext = r
  }
  dq_prev_ = dq;
  t_ = t;
  estimate(t, reading_S);
  return out_.status;
}

Status ContactEstimator::update_with(double t, const Eigen::Ref<const VectorX>& q,
                                     const Eigen::Ref<const VectorX>& dq,
                                     const Eigen::Ref<const VectorX>& ddq,
                                     const Eigen::Ref<const VectorX>& tau_ext,
                                     const Eigen::Ref<const VectorX>& tau,
                                     const Vector6& reading_S) noexcept {
  Status s = Status::success();
  if (!std::isfinite(t)) {
    s = {StatusCode::kNonFinite, Channel::kTime, 0};
  } else if (initialized_ && !(t > t_)) {
    s = {StatusCode::kNonIncreasingTime, Channel::kTime, 0};
  }
  if (s.ok()) s = check_vector(q, n_, Channel::kPosition);
  if (s.ok()) s = check_vector(dq, n_, Channel::kVelocity);
  if (s.ok()) s = check_vector(ddq, n_, Channel::kAcceleration);
  if (s.ok()) s = check_vector(tau_ext, n_, Channel::kTorque);
  if (s.ok()) s = check_vector(tau, n_, Channel::kTorque);
  if (s.ok()) s = validate_reading(reading_S);
  if (!s.ok()) {
    fail(t, s);
    return s;
  }
  Data& data = observer_.workspace();
  forward_kinematics(observer_.model(), data, q);
  ddq_ = ddq;
  tau_ext_ = tau_ext;
  rnea_no_kinematics(observer_.model(), data, dq, ddq_);
  initialized_ = true;
  t_ = t;
  out_.status = Status::success();
  estimate(t, reading_S);
  return out_.status;
}

void ContactEstimator::estimate(double t, const Vector6& reading_S) noexcept {
  const Model& model = observer_.model();
  const Data& data = observer_.workspace();
  const Status status = out_.status;
  {
    // Fresh output, keeping the residual buffer.
    VectorX residual = std::move(out_.residual);
    out_ = ContactEstimate{};
    out_.residual = std::move(residual);
  }
  out_.status = status;
  out_.t = t;
  out_.residual = tau_ext_;
  std::uint32_t flags = 0;

  const SensorType sensor = options_.sensor.type;
  const bool has_sensor = sensor != SensorType::kNone && status.ok();
  const Pose& X_WS = options_.sensor.pose;
  Vector3 F = Vector3::Constant(kNaN);     // F̂_ext
  Vector3 dn_s = Vector3::Constant(kNaN);  // n_m − ñ_g, about O_s (F/T)
  bool taring = false;
  if (has_sensor) {
    // What the robot would discharge with this motion and no contact (f̃_g, ñ_g), world, about O_s.
    const Vector6 predicted_W = sensor_reading_world(data, X_WS.translation);
    Vector6 predicted_S;
    predicted_S.head<3>().noalias() = X_WS.rotation.transpose() * predicted_W.head<3>();
    predicted_S.tail<3>().noalias() = X_WS.rotation.transpose() * predicted_W.tail<3>();
    if (tare_count_ < tare_target_) {
      // Tare: bias = mean(reading − predicted reading) over the requested samples (no contact).
      tare_sum_ += reading_S - predicted_S;
      if (++tare_count_ == tare_target_) {
        bias_S_ = tare_sum_ / tare_target_;
        if (sensor == SensorType::kForce) bias_S_.tail<3>().setZero();
        tare_target_ = 0;
        tare_count_ = 0;
      } else {
        taring = true;
        flags |= EstimateFlag::kTaring;
      }
    }
    const Vector6 corrected_S = reading_S - bias_S_;
    // Readings rotated from the sensor frame into W (moments stay about O_s).
    F.noalias() = X_WS.rotation * corrected_S.head<3>();
    F -= predicted_W.head<3>();  // (11) F̂_ext = f_m − f̃_g
    if (sensor == SensorType::kForceTorque) {
      dn_s.noalias() = X_WS.rotation * corrected_S.tail<3>();
      dn_s -= predicted_W.tail<3>();  // n_m − ñ_g = M_ext + r_{s,p} × F_ext   (13)
    }
  }

  // Detection and isolation.
  const double base_force = has_sensor && !taring ? F.norm() : kNaN;
  const DetectionResult& det = detector_.update(t, tau_ext_, base_force);
  out_.contact = det.contact;
  if (det.contact) flags |= EstimateFlag::kContact;
  if (det.pending) flags |= EstimateFlag::kPending;
  if (det.contact && det.base_only) flags |= EstimateFlag::kBaseOnly;

  const bool known_point = options_.contact.model == ContactModel::kKnownPoint;
  int link = det.contact ? det.link : -1;
  if (known_point) {
    if (det.contact && det.link != options_.contact.link) flags |= EstimateFlag::kLinkMismatch;
    link = options_.contact.link;
  }
  if (has_sensor) {
    out_.force_W = F;
    flags |= EstimateFlag::kForce;
  }
  if (link < 0) {
    out_.flags = flags;
    disagreement_on_ = false;
    have_disagreement_edge_ = false;
    return;
  }
  out_.link = link;
  out_.link_name = model.bodies[static_cast<std::size_t>(link)].name;
  const Pose& X_WL = data.X_WB[static_cast<std::size_t>(link)];
  const Vector3& O_l = X_WL.translation;

  // The wrench as (F̂, M̄) with M̄ the moment about O_l (M̄ = M_ext + r_{l,p} × F_ext).
  Vector3 M_bar = Vector3::Constant(kNaN);
  bool wrench_ok = false;
  bool damped = false;
  if (status.ok()) {
    point_jacobian(model, data, link, O_l, J_);  // J_l of O_l: [J_v,l; J_ω,l], zero beyond l
    if (sensor == SensorType::kForceTorque) {
      // C (17): M̃ = n_m − ñ_g − r_{s,l} × F̂, the moment about O_l.
      M_bar = dn_s - (O_l - X_WS.translation).cross(F);
      wrench_ok = true;
    } else if (sensor == SensorType::kForce) {
      // D (26): M̄̂ = (J_ω,lᵀ)# (τ̂_1:l − J_v,lᵀ F̂), rank J_ω,l = 3 required.
      b_ = tau_ext_;
      b_.noalias() -= J_.topRows<3>().transpose() * F;
      Vector3 x;
      const DlsInfo info = damped_solve<3>(J_.bottomRows<3>(), link, b_, options_.solver, x,
                                           spectrum_min_, spectrum_max_, spectrum_size_);
      out_.condition_number = info.condition;
      if (info.rank_ok) {
        M_bar = x;
        wrench_ok = true;
        damped = info.damped;
      }
    } else {
      // E (27): W̄ = (J_lᵀ)# τ̂_1:l, rank J_l = 6 required.
      Vector6 x;
      const DlsInfo info = damped_solve<6>(J_, link, tau_ext_, options_.solver, x, spectrum_min_,
                                           spectrum_max_, spectrum_size_);
      out_.condition_number = info.condition;
      if (info.rank_ok) {
        F = x.head<3>();
        M_bar = x.tail<3>();
        wrench_ok = true;
        damped = info.damped;
        out_.force_W = F;
        flags |= EstimateFlag::kForce;
      }
    }
  }
  if (damped) flags |= EstimateFlag::kIllConditioned;
  if (!wrench_ok && status.ok()) flags |= EstimateFlag::kUnobservable;

  if (known_point) {
    const Vector3 p_W = X_WL.act(options_.contact.point);
    out_.point_W = p_W;
    out_.point_L = options_.contact.point;
    flags |= EstimateFlag::kKnownPoint;
    if (wrench_ok) {
      // (16) M̂_ext = M̄ − r_{l,p} × F̂  (= n_m − ñ_g − r_{s,p} × F̂ with the F/T sensor)
      out_.moment_W = M_bar - (p_W - O_l).cross(F);
      flags |= EstimateFlag::kMoment;
    }
  } else if (wrench_ok && det.contact) {
    const double f2 = F.squaredNorm();
    if (f2 > 0.0 && std::isfinite(f2)) {
      // (19)-(20) r̂_{l,p} = −S#(F̂) M̃ = F̂ × M̃ / ‖F̂‖²,  p̂ = O_l + r̂: the point of the line of
      // action nearest O_l; (21) p(λ) = p̂ + λ F̂/‖F̂‖.
      out_.line_point_W = O_l + F.cross(M_bar) / f2;
      out_.line_direction_W = F / std::sqrt(f2);
      flags |= EstimateFlag::kLineOfAction;
      out_.flags = flags;
      locate_on_surface(link);
      flags = out_.flags;
    }
  }

  // Consistency of the base wrench (or the fitted wrench) with the residual: a single wrench on
  // link l must reproduce τ̂_ext = J_lᵀ (F̂, M̄) on every joint, within τ_min. Two contacts, or a
  // contact on another link, break it. Not judged while damped (the fit is biased on purpose),
  // and only once it has lasted longer than the residual's transient.
  bool inconsistent = false;
  if (det.contact && wrench_ok && !damped && link > 0) {
    Vector6 w;
    w << F, M_bar;
    tau_pred_.noalias() = J_.transpose() * w;
    const VectorX& tau_min = detector_.tau_min();
    for (int i = 0; i < n_; ++i) {
      if (std::abs(tau_pred_[i] - tau_ext_[i]) > tau_min[i]) inconsistent = true;
    }
  }
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
  out_.flags = flags;
}

void ContactEstimator::locate_on_surface(int link) noexcept {
  const auto l = static_cast<std::size_t>(link);
  if (geometry_.body_shapes[l].empty()) {
    out_.flags |= EstimateFlag::kNoGeometry;
    return;
  }
  const Pose& X_WL = observer_.workspace().X_WB[l];
  const SurfacePointResult res =
      intersect_line_with_body(geometry_, link, X_WL, out_.line_point_W, out_.line_direction_W);
  if (res.hit) {
    out_.point_W = res.entry.point_W;  // smallest λ: the pushing point (21)
    out_.surface_distance = 0.0;
    out_.flags |= EstimateFlag::kSurfacePoint;
  } else if (std::isfinite(res.distance)) {
    out_.point_W = res.closest_point_W;  // the line misses the link: nearest surface point
    out_.surface_distance = res.distance;
    out_.flags |= EstimateFlag::kSurfaceMissed;
  } else {
    out_.flags |= EstimateFlag::kNoGeometry;
    return;
  }
  out_.point_L.noalias() = X_WL.rotation.transpose() * (out_.point_W - X_WL.translation);
}

}  // namespace extwrench
