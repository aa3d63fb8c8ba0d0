#include "extwrench/sim/force_profile.hpp"

#include <algorithm>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"

namespace extwrench::sim {

void ForceProfile::resolve(const Model& model) {
  const auto f = model.find_frame(frame);
  if (!f)
    throw Error("force profile: frame '" + frame + "' is not a frame of robot '" + model.name +
                "'");
  const Frame& fr = model.frames[static_cast<std::size_t>(*f)];
  body = fr.body;
  X_BF = fr.placement;
}

double ForceProfile::scale(double t) const noexcept {
  if (t < start || t > end) return 0.0;
  if (ramp <= 0.0) return 1.0;
  return std::clamp(std::min(t - start, end - t) / ramp, 0.0, 1.0);
}

bool ForceProfile::evaluate(double t, const Data& data, ExternalWrench& out) const noexcept {
  const double s = scale(t);
  if (s == 0.0 || body < 0) return false;
  const Pose X_WF = data.X_WB[static_cast<std::size_t>(body)] * X_BF;
  out.body = body;
  out.point_W = X_WF.act(point_F);
  if (axes == Axes::kFrame) {
    out.force_W = s * (X_WF.rotation * force);
    out.moment_W = s * (X_WF.rotation * moment);
  } else {
    out.force_W = s * force;
    out.moment_W = s * moment;
  }
  return true;
}

int evaluate_forces(std::span<const ForceProfile> profiles, double t, const Data& data,
                    std::vector<ExternalWrench>& out) {
  out.clear();
  ExternalWrench w;
  for (const ForceProfile& p : profiles) {
    if (p.evaluate(t, data, w)) out.push_back(w);
  }
  return static_cast<int>(out.size());
}

void external_joint_torques(const Model& model, const Data& data,
                            std::span<const ExternalWrench> wrenches, Matrix6X& jacobian,
                            Eigen::Ref<VectorX> tau_ext) {
  tau_ext.setZero();
  for (const ExternalWrench& w : wrenches) {
    // τ_ext = J_pᵀ [F; M]: J_v of the point for the force, J_ω of the link for the moment (2)
    point_jacobian(model, data, w.body, w.point_W, jacobian);
    tau_ext.noalias() += jacobian.topRows<3>().transpose() * w.force_W;
    tau_ext.noalias() += jacobian.bottomRows<3>().transpose() * w.moment_W;
  }
}

}  // namespace extwrench::sim
