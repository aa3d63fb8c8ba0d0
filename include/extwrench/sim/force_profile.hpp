// External forces applied to the simulated robot: the truth the estimators must recover.
#pragma once

#include <limits>
#include <span>
#include <string>
#include <vector>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"

namespace extwrench::sim {

/// A force (and optional pure moment) applied at a point fixed on a body.
///
/// The point is given in a named frame of the model (a link frame, a DH frame, a tool frame);
/// the force and moment are constant either in that frame (they turn with the link: the
/// paper's ⁶F_ext,6) or in the world frame. The profile is active in [start, end]; it rises
/// linearly over `ramp` seconds after start and falls over `ramp` seconds before end
/// (ramp = 0: a step).
struct ForceProfile {
  enum class Axes { kFrame, kWorld };

  std::string frame;                  ///< name of a Model frame (resolved by resolve())
  Axes axes = Axes::kFrame;           ///< axes in which force / moment are constant
  Vector3 force = Vector3::Zero();    ///< [N]
  Vector3 moment = Vector3::Zero();   ///< pure moment [N m]
  Vector3 point_F = Vector3::Zero();  ///< application point in `frame` F [m]
  double start = 0.0;                 ///< [s]
  double end = std::numeric_limits<double>::infinity();  ///< [s]
  double ramp = 0.0;                                     ///< [s]

  // Resolved against a Model:
  int body = -1;  ///< body the frame is attached to
  Pose X_BF;      ///< placement of the frame on the body

  /// Looks the frame up in `model`; throws extwrench::Error naming it when missing.
  void resolve(const Model& model);
  /// Scale in [0, 1] of the profile at time t (0 outside [start, end]).
  [[nodiscard]] double scale(double t) const noexcept;
  /// The world-frame wrench at time t, after forward_kinematics on `data`. Returns false (and
  /// leaves `out` untouched) when the profile is inactive at t.
  bool evaluate(double t, const Data& data, ExternalWrench& out) const noexcept;
};

/// Evaluates every active profile at t into `out` (cleared first; capacity reserved by the
/// caller to avoid allocation). Returns the number of active profiles.
int evaluate_forces(std::span<const ForceProfile> profiles, double t, const Data& data,
                    std::vector<ExternalWrench>& out);

/// τ_ext = Σ_k J_kᵀ W_k (eqs. 1–2) from the point Jacobians of the contacts, after
/// forward_kinematics. `jacobian` is a 6×n scratch matrix. Independent of the RNEA path.
void external_joint_torques(const Model& model, const Data& data,
                            std::span<const ExternalWrench> wrenches, Matrix6X& jacobian,
                            Eigen::Ref<VectorX> tau_ext);

}  // namespace extwrench::sim
