// One sample of a robot log: what the robot measured, and (in simulation) the truth.
// The CSV form is documented in docs/log_format.md (io/log.hpp reads and writes it).
#pragma once

#include <string>

#include "extwrench/core/types.hpp"

namespace extwrench {

/// Ground truth of a sample, world frame. With several simultaneous contacts, `link` lists the
/// link names joined by '+', force and moment are sums and point is the first contact's.
struct Truth {
  std::string link;                    ///< empty when free
  int body = -1;                       ///< body index of the (first) contact, -1 when free
  int contacts = 0;                    ///< number of active contacts
  Vector3 force_W = Vector3::Zero();   ///< F_ext [N]
  Vector3 moment_W = Vector3::Zero();  ///< pure moment M_ext [N m]
  Vector3 point_W = Vector3::Zero();   ///< contact point p [m]; NaN when a log has no true_p*
  VectorX tau_ext;                     ///< (n) τ_ext [N m | N]
};

struct Sample {
  double t = 0.0;                       ///< [s]
  VectorX q;                            ///< (n) [rad | m]
  VectorX dq;                           ///< (n) [rad/s | m/s]; empty when not logged
  VectorX tau;                          ///< (n) commanded torque [N m | N]
  bool has_force = false;               ///< fs_x..fs_z present
  bool has_moment = false;              ///< ms_x..ms_z present
  Vector6 reading_S = Vector6::Zero();  ///< base reading [f_m; n_m], sensor frame, about O_s
  bool has_truth = false;               ///< true_* columns present
  bool has_true_tau_ext = false;        ///< true_tau_ext1..n present
  Truth truth;
};

}  // namespace extwrench
