// One estimator over all of Table I (docs/estimator.md): from q, q̇, τ and, when present, a base
// sensor, say whether the robot is touched, on which link, with what force and moment, and where.
//
// The estimator owns its Model (payloads edit it), its Data, the collision geometry, the
// momentum observer's state and the detector: it is a value (copy and move freely). update()
// runs these stages in the order a sample flows, each reading what the one before left:
//   1. momentum and bias terms   dynamics pass on data_ (momentum.hpp)
//   2. observer integration      r ≈ τ_ext (momentum_observer.hpp, eq. 4)
//   3. acceleration route        q̈̂ by route (a) or (b)
//   4. ground wrench             (f̃_g, ñ_g), the no-contact base wrench, and the route's τ̂_ext
//   5. base-sensor reading       tare, F̂_ext (11), n_m − ñ_g (13)       (base_sensor.hpp)
//   6. detection                 thresholds, hysteresis, min_duration     (detection.hpp)
//   7. isolation                 the contact link                         (detection.hpp)
//   8. Table I case              (F̂, M̄) by case A–E, known point (15)   (wrench_cases.hpp)
//   9. contact point             line of action (21) → link surface       (localization.hpp)
//  10. uncertainty               Σ and 1-σ of every estimate, `uncertain` (uncertainty.hpp)
// then the consistency of the wrench with τ̂_ext (wrench_cases.hpp). Damped least squares
// (Remark 6) for D and E: damped_least_squares.hpp.
//
// Real time: update() is noexcept, allocation-free, and validates every input before touching
// any state (bad inputs: a Status naming the channel and index; the next good sample gives
// bit-identical results to a run that never saw the bad one).
#pragma once

#include <cmath>
#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/estimation/detection.hpp"
#include "extwrench/estimation/estimator_options.hpp"
#include "extwrench/estimation/wrench_cases.hpp"
#include "extwrench/geometry/shapes.hpp"
#include "extwrench/observer/momentum_observer.hpp"
#include "extwrench/observer/residual_filter.hpp"

namespace extwrench {

class ContactEstimator {
 public:
  /// Copies the model and geometry (the estimator owns what it uses). Throws extwrench::Error if
  /// the options do not fit the model (validate(options, model)) or the geometry has another
  /// number of bodies than the model.
  ContactEstimator(Model model, GeometryModel geometry, EstimatorOptions options);

  /// Starts at time t (observer reset, filters and detection cleared, tare restarted if
  /// configured, a tare requested by request_tare() and not finished dropped: its samples came
  /// before). τ is the torque held over the first interval. The sensor bias a finished tare or
  /// set_sensor_bias() gave is kept (with drift tracking, which moves it, it starts again from
  /// the configured one), as is a payload. kNotInitialized on a moved-from estimator.
  [[nodiscard]] Status reset(double t, const Eigen::Ref<const VectorX>& q,
                             const Eigen::Ref<const VectorX>& dq,
                             const Eigen::Ref<const VectorX>& tau) noexcept;
  /// reset(s.t, s.q, s.dq, s.tau).
  [[nodiscard]] Status reset(const Sample& s) noexcept { return reset(s.t, s.q, s.dq, s.tau); }

  /// One sample of any sensor type: the base reading s.reading_S is used when the configured sensor
  /// needs it, and must then be present (s.has_force, and s.has_moment for an F/T sensor; else
  /// kWrongSize on the base-wrench channel). Returns result().status.
  [[nodiscard]] Status update(const Sample& s) noexcept;
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
  /// With options.residual_cutoff > 0 the supplied τ̂_ext goes through the same low-pass as the
  /// observer's residual would (started at rest on the first value).
  [[nodiscard]] Status update_with(double t, const Eigen::Ref<const VectorX>& q,
                                   const Eigen::Ref<const VectorX>& dq,
                                   const Eigen::Ref<const VectorX>& ddq,
                                   const Eigen::Ref<const VectorX>& tau_ext,
                                   const Eigen::Ref<const VectorX>& tau,
                                   const Vector6& reading_S) noexcept;

  /// Re-estimates the sensor bias over the next `samples` samples (robot free of contact).
  void request_tare(int samples) noexcept { tare_.request(samples); }
  /// Sensor bias [f; n] in the sensor frame (subtracted from every reading).
  [[nodiscard]] const Vector6& sensor_bias() const noexcept { return tare_.bias_S; }
  /// kNonFinite (index: the entry) for a NaN or Inf entry, and the bias is left as it was: every
  /// later force would be NaN.
  Status set_sensor_bias(const Vector6& bias_S) noexcept {
    for (int i = 0; i < 6; ++i)
      if (!std::isfinite(bias_S[i])) return {StatusCode::kNonFinite, Channel::kBaseWrench, i};
    tare_.bias_S = bias_S;
    return Status::success();
  }

  /// Adds a payload (mass properties in the frame of `body`) to body `body` of model(),
  /// replacing any previous payload; the observer is re-anchored so that r stays continuous.
  /// Allocation-free. kWrongSize for a bad body index, kNonFinite for a NaN/Inf entry or a
  /// negative mass, kNotInitialized on a moved-from estimator (then nothing changes).
  [[nodiscard]] Status set_payload(int body, const Inertia& payload) noexcept;
  /// Removes the payload (same continuity as set_payload); nothing on a moved-from estimator.
  void clear_payload() noexcept { apply_payload(-1, nullptr); }

  /// Pages in the code and data the first contact needs (warm_up_geometry on this estimator's
  /// collision shapes), without changing any state. The constructor does it; call it again on
  /// the loop's thread right before the loop (docs/estimator.md#hard-real-time).
  void warm_up() const noexcept;

  [[nodiscard]] const ContactEstimate& result() const noexcept { return out_; }
  /// The model in use (payload included); body names: model().bodies[result().link].name.
  [[nodiscard]] const Model& model() const noexcept { return model_; }
  /// The dynamics workspace after the last sample (poses X_WB of its q, among others).
  [[nodiscard]] const Data& data() const noexcept { return data_; }
  [[nodiscard]] const GeometryModel& geometry() const noexcept { return geometry_; }
  [[nodiscard]] const EstimatorOptions& options() const noexcept { return options_; }
  [[nodiscard]] const MomentumObserver& observer() const noexcept { return observer_; }
  [[nodiscard]] const ContactDetector& detector() const noexcept { return detector_; }
  /// q̈̂ of the last sample (n); NaN entries when it was not needed (no sensor, residual route).
  [[nodiscard]] const VectorX& acceleration() const noexcept { return ddq_; }

 private:
  // Stages of update(), in order (see the header comment).
  void momentum_and_bias_terms_stage(const Eigen::Ref<const VectorX>& q,
                                     const Eigen::Ref<const VectorX>& dq) noexcept;
  Status acceleration_route(double dt, const Eigen::Ref<const VectorX>& dq,
                            const Eigen::Ref<const VectorX>& tau) noexcept;
  void ground_wrench(const Eigen::Ref<const VectorX>& dq) noexcept;
  void estimate(double t, const Eigen::Ref<const VectorX>& dq,
                const Vector6& reading_S) noexcept;  // stages 5–9
  BaseWrench base_sensor_reading(const Vector6& reading_S, std::uint32_t& flags) noexcept;
  /// The fit is fit_ or the chosen candidate's (valid until the next update).
  const WrenchFit& table_one_case(int link, const BaseWrench& base, std::uint32_t& flags) noexcept;
  /// The sensor's force now, for the release (NaN when unknown): the smaller of the two routes
  /// (`either`) and the one with q̈ measured (`measured`, independent of the contact point).
  struct ReleaseForces {
    double either = ContactDetector::kNoReleaseForce;
    double measured = ContactDetector::kNoReleaseForce;
  };
  ReleaseForces sensor_release_forces(const BaseWrench& base) noexcept;
  void differentiate_velocity(double dt, const Eigen::Ref<const VectorX>& dq) noexcept;
  void known_point_force(int link, WrenchFit& fit, std::uint32_t& flags) noexcept;
  int geometric_isolation(int residual_link, const BaseWrench& base, std::uint32_t& flags) noexcept;
  void contact_point(int link, const WrenchFit& fit, bool contact, std::uint32_t& flags) noexcept;
  void consistency(double t, int link, bool contact, const WrenchFit& fit,
                   std::uint32_t& flags) noexcept;
  void track_drift(double t, const DetectionResult& det, const BaseWrench& base) noexcept;
  void uncertainty(int link, const WrenchFit& fit, std::uint32_t& flags) noexcept;
  void sensor_force_uncertainty() noexcept;
  void partial_uncertainty(int link, const WrenchFit& fit, std::uint32_t& flags) noexcept;

  Status validate_sample(double t, const Eigen::Ref<const VectorX>& q,
                         const Eigen::Ref<const VectorX>& dq, const Eigen::Ref<const VectorX>& tau,
                         const Vector6& reading_S) const noexcept;
  void fail(double t, Status s) noexcept;
  void begin_output(double t) noexcept;
  /// out_ back to a default ContactEstimate, keeping its residual and torque_offset buffers (no
  /// allocation; their values are the caller's to set).
  void clear_output() noexcept;
  void apply_payload(int body, const Inertia* payload) noexcept;

  EstimatorOptions options_;
  Model model_;
  std::vector<Inertia> nominal_inertia_;  ///< bodies' inertia without payload
  int payload_body_ = -1;
  Data data_;
  GeometryModel geometry_;
  MomentumObserver observer_;
  bool inertia_corrected_ = false;  ///< options_.inertia_correction is not zero
  ResidualFilter residual_filter_;  ///< options_.residual_cutoff on τ̂_ext (off at 0)
  ResidualFilter velocity_filter_;  ///< options_.velocity_cutoff on q̇ (off at 0)
  VectorX dq_filtered_;             ///< q̇ through velocity_filter_ (n)
  ContactDetector detector_;
  IsolationRule isolation_rule_ = IsolationRule::kResidual;  ///< options_.isolation resolved
  IsolationWorkspace isolation_ws_;
  /// The link geometric isolation chose in this sample (its fit, line and entry are in
  /// isolation_ws_.tested), −1: none.
  int geometric_link_ = -1;
  NoiseModel noise_;  ///< options_.uncertainty as variances, the sensor's in W
  int n_ = 0;
  bool differentiation_ = false;  ///< route (a)
  bool need_ddq_ = false;         ///< q̈̂ needed: a sensor, or route (a)
  double settle_time_ = 0.0;      ///< residual / filter transient (5 time constants) [s]

  // State besides the observer's.
  bool initialized_ = false;
  double t_ = 0.0;
  VectorX dq_prev_, ddq_filtered_;  ///< route (a); with a base sensor, the release too
  bool have_dq_prev_ = false;
  SensorTare tare_;
  bool disagreement_on_ = false, have_disagreement_edge_ = false;
  double disagreement_edge_ = 0.0;
  int release_link_ = -1;  ///< contact link of the last sample (−1: none), for the release
  Vector3 release_point_L_ = Vector3::Zero();  ///< its contact point (link frame), else O_l
  VectorX initial_offset_, drift_delta_;       ///< drift tracking: configured offsets, one step
  double drift_quiet_since_ = 0.0;             ///< last sample with contact, pending or raw [s]
  double drift_t_prev_ = 0.0;
  SpectrumGuess spectrum_;  ///< of J Jᵀ at the last damped solve (cases D, E); size 0 after reset
  int spectrum_link_ = -1;  ///< the link of that solve (stage 8's last), −1 after reset
  Vector3 surface_normal_W_ = Vector3::Zero();  ///< outward normal at the surface point (stage 9)

  // Scratch, sized once.
  VectorX ddq_, tau_ext_, b_, tau_pred_, tau_eff_;
  VectorX dynamic_torque_;  ///< τ_dyn = τ − τ_f − g + τ̂_ext, for thresholds that follow it
  Matrix6X J_;
  /// ∂f_0/∂q̈ (6×n): column j−1 = Ic_j S_j, the root wrench per unit q̈_j (stage 4, route (b));
  /// the release force's G, H. Valid for this sample when root_wrench_dddq_valid_.
  Matrix6X root_wrench_dddq_;
  bool root_wrench_dddq_valid_ = false;
  bool ddq_supplied_ = false;  ///< this sample's q̈̂ came from the caller (update_with)
  /// B⁻¹ [J_vᵀ r] (n×4, row-major: one row operation per step of the substitutions), release
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> minv_jvt_r_;
  WrenchFit fit_;  ///< stage 8's fit when isolation did not make it
  ContactEstimate out_;
  // LDLᵀ of B(q) for q̈̂ with storage inside the object (up to kInlineJoints joints): the
  // fixed-capacity factorisation and solves are faster than the dynamic-size ones in Data.
  static constexpr int kInlineJoints = 12;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kInlineJoints, kInlineJoints> mass_ldlt_;
};

}  // namespace extwrench
