// One estimator over all of Table I (SPEC §4): from q, q̇, τ and, when present, a base sensor,
// say whether the robot is touched, on which link, with what force and moment, and where.
//
// Per sample (update): the momentum residual (observer) → q̈̂ and τ̂_ext (route (a) or (b)) → the
// no-contact ground wrench (f̃_g, ñ_g) from one RNEA pass → the sensor reading minus its bias,
// rotated into W → detection and isolation → the case of Table I:
//   A  F̂ = f_m − f̃_g                                  (11)   force or F/T sensor, any link
//   B  M̂ = n_m − ñ_g − r_{s,p} × F̂                    (16)   F/T, known point
//   C  M̃ = n_m − r_{s,l} × F̂ − ñ_g,  r̂ = F̂ × M̃/‖F̂‖²  (17–20) F/T, pure force
//   D  M̄̂ = (J_ω,lᵀ)# (τ̂_1:l − J_v,lᵀ F̂)               (26)   force sensor, rank J_ω,l = 3
//   E  W̄ = (J_lᵀ)# τ̂_1:l                              (27)   no sensor, rank J_l = 6
// then the line of action p̂ + λ F̂/‖F̂‖ (21) meets the link's collision shapes: the smallest λ is
// the pushing point. O_l is the origin of body l's frame, J_l the Jacobian of that point.
//
// Damped least squares (Remark 6) for D and E. With σ_1 ≥ … ≥ σ_min the singular values of J
// (3×l or 6×l) and ε = σ_1 / max_condition:
//   μ² = 0 if σ_min ≥ ε,   μ² = ε² − σ_min² otherwise,   x = (J Jᵀ + μ² I)⁻¹ J b,
// so the solution is exact up to the condition number max_condition, the damping grows smoothly
// as σ_min falls below ε, and the gain along the weakest direction stays ≤ 1/ε (bounded output).
// Observability is a rank test: σ_min ≤ rank_tolerance · σ_1 means the moment / point (D) or the
// wrench (E) cannot be estimated at this configuration (kUnobservable, NaN), whatever the link.
//
// Real time: update() is noexcept, allocation-free, and validates every input before touching
// any state (bad inputs: a Status naming the channel and index; the next good sample gives
// bit-identical results to a run that never saw the bad one).
#pragma once

#include <Eigen/Cholesky>
#include <optional>

#include "extwrench/estimation/contact_detector.hpp"
#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/geometry/shapes.hpp"
#include "extwrench/observer/momentum_observer.hpp"

namespace extwrench {

struct SensorOptions {
  SensorType type = SensorType::kNone;
  Pose pose;  ///< X_WS: pose of the sensor frame in the robot's root frame
  int tare_samples =
      0;  ///< > 0: bias = mean(reading − predicted) over the first samples after reset
};

struct ContactOptions {
  ContactModel model = ContactModel::kPureForce;
  int link = -1;                    ///< known point: body index of the contact link
  Vector3 point = Vector3::Zero();  ///< known point: p in the link frame [m]
};

struct PayloadOptions {
  int body = -1;    ///< body carrying the payload
  Inertia inertia;  ///< mass properties in that body's frame
};

struct SolverOptions {
  double max_condition = 1e3;  ///< κ above which damping starts (damped least squares)
  /// σ_min/σ_max at or below which the rank is deficient. σ comes from the eigenvalues of J Jᵀ,
  /// accurate to ~1e-8 σ_max, so the tolerance must stay well above that.
  double rank_tolerance = 1e-6;
};

struct EstimatorOptions {
  SensorOptions sensor;
  ContactOptions contact;
  VectorX observer_gain = VectorX::Constant(1, 100.0);  ///< K [1/s], size 1 or n
  DetectionOptions detection;
  AccelerationRoute acceleration = AccelerationRoute::kResidual;
  double differentiation_cutoff = 50.0;   ///< [Hz] low-pass of the differentiated q̇ (route (a))
  std::optional<JointFriction> friction;  ///< default: the model's Joint::damping / friction
  std::optional<PayloadOptions> payload;
  SolverOptions solver;
};

class ContactEstimator {
 public:
  /// Copies the model and geometry (the estimator owns what it uses). Throws extwrench::Error if
  /// the options do not fit the model (sizes, link indices, ranges) or the model is not a serial
  /// chain (isolation by joint index needs one).
  ContactEstimator(Model model, GeometryModel geometry, EstimatorOptions options);
  // result().link_name views the owned model: neither copied nor moved (hold it by unique_ptr).
  ContactEstimator(const ContactEstimator&) = delete;
  ContactEstimator& operator=(const ContactEstimator&) = delete;

  /// Starts at time t (observer reset, filters and detection cleared, tare restarted if
  /// configured). τ is the torque held over the first interval.
  [[nodiscard]] Status reset(double t, const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq,
                             const Eigen::Ref<const VectorX>& tau) noexcept;

  /// One sample with a base reading [f; n] in the sensor frame (moment about the sensor origin;
  /// a 3-axis sensor uses the first three entries only). Returns result().status.
  [[nodiscard]] Status update(double t, const Eigen::Ref<const VectorX>& q,
                              const Eigen::Ref<const VectorX>& dq,
                              const Eigen::Ref<const VectorX>& tau,
                              const Vector6& reading_S) noexcept;
  /// One sample without a base sensor (sensor type none).
  [[nodiscard]] Status update(double t, const Eigen::Ref<const VectorX>& q,
                              const Eigen::Ref<const VectorX>& dq,
                              const Eigen::Ref<const VectorX>& tau) noexcept;

  /// Expert entry: q̈̂ and τ̂_ext supplied by the caller (another observer, or exact values in
  /// tests); runs tare, detection, isolation and Table I, but not the observer. t must increase.
  [[nodiscard]] Status update_with(double t, const Eigen::Ref<const VectorX>& q,
                                   const Eigen::Ref<const VectorX>& dq,
                                   const Eigen::Ref<const VectorX>& ddq,
                                   const Eigen::Ref<const VectorX>& tau_ext,
                                   const Eigen::Ref<const VectorX>& tau,
                                   const Vector6& reading_S) noexcept;

  /// Re-estimates the sensor bias over the next `samples` samples (robot free of contact).
  void request_tare(int samples) noexcept;
  /// Sensor bias [f; n] in the sensor frame (subtracted from every reading).
  [[nodiscard]] const Vector6& sensor_bias() const noexcept { return bias_S_; }
  void set_sensor_bias(const Vector6& bias_S) noexcept { bias_S_ = bias_S; }

  /// Payload on a body, at run time (see MomentumObserver::set_payload).
  [[nodiscard]] Status set_payload(int body, const Inertia& payload) noexcept;
  void clear_payload() noexcept { observer_.clear_payload(); }

  [[nodiscard]] const ContactEstimate& result() const noexcept { return out_; }
  [[nodiscard]] const Model& model() const noexcept { return observer_.model(); }
  [[nodiscard]] const GeometryModel& geometry() const noexcept { return geometry_; }
  [[nodiscard]] const EstimatorOptions& options() const noexcept { return options_; }
  [[nodiscard]] const MomentumObserver& observer() const noexcept { return observer_; }
  [[nodiscard]] const ContactDetector& detector() const noexcept { return detector_; }
  /// q̈̂ of the last sample (n); NaN entries when it was not needed (no sensor, residual route).
  [[nodiscard]] const VectorX& acceleration() const noexcept { return ddq_; }

 private:
  Status validate_reading(const Vector6& reading_S) const noexcept;
  Status validate_common(double t, const Eigen::Ref<const VectorX>& q,
                         const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& tau,
                         const Vector6& reading_S) const noexcept;
  void fail(double t, Status s) noexcept;
  void estimate(double t, const Vector6& reading_S) noexcept;
  void locate_on_surface(int link) noexcept;

  EstimatorOptions options_;
  GeometryModel geometry_;
  MomentumObserver observer_;
  ContactDetector detector_;
  int n_ = 0;
  double settle_time_ = 0.0;  ///< residual / filter transient (5 time constants) [s]

  // State besides the observer's.
  bool initialized_ = false;
  double t_ = 0.0;
  VectorX dq_prev_, ddq_filtered_;  ///< route (a)
  bool have_dq_prev_ = false;
  Vector6 bias_S_ = Vector6::Zero();
  Vector6 tare_sum_ = Vector6::Zero();
  int tare_count_ = 0, tare_target_ = 0;
  bool disagreement_on_ = false, have_disagreement_edge_ = false;
  double disagreement_edge_ = 0.0;
  // Extreme eigenvectors of J Jᵀ at the last sample (cases D, E): where the next sample's
  // power / inverse iterations start. spectrum_size_ = 3 or 6 when valid, 0 after reset.
  Vector6 spectrum_min_ = Vector6::Zero(), spectrum_max_ = Vector6::Zero();
  int spectrum_size_ = 0;

  // Scratch, sized once.
  VectorX ddq_, tau_ext_, b_, tau_pred_, tau_eff_;
  Matrix6X J_;
  ContactEstimate out_;
  // LDLᵀ of B(q) for q̈̂ with storage inside the object (up to kInlineJoints joints): the
  // fixed-capacity factorisation and solves are faster than the dynamic-size ones in Data.
  static constexpr int kInlineJoints = 12;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kInlineJoints, kInlineJoints> mass_ldlt_;
};

}  // namespace extwrench
