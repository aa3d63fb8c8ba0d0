#include "extwrench/observer/friction.hpp"

#include <algorithm>
#include <cmath>

#include "extwrench/core/error.hpp"

namespace extwrench {

JointFriction JointFriction::none(int n) {
  JointFriction f;
  f.viscous = VectorX::Zero(n);
  f.coulomb = VectorX::Zero(n);
  return f;
}

JointFriction JointFriction::from_model(const Model& model) {
  JointFriction f = none(model.nq());
  for (int i = 1; i <= model.nq(); ++i) {
    f.viscous[i - 1] = model.joints[static_cast<std::size_t>(i)].damping;
    f.coulomb[i - 1] = model.joints[static_cast<std::size_t>(i)].friction;
  }
  return f;
}

bool JointFriction::is_zero() const noexcept {
  return (viscous.size() == 0 || viscous.isZero(0.0)) &&
         (coulomb.size() == 0 || coulomb.isZero(0.0));
}

void friction_torque(const JointFriction& friction, const Eigen::Ref<const VectorX>& dq,
                     Eigen::Ref<VectorX> out) noexcept {
  const double inv_vs = 1.0 / friction.smoothing_velocity;
  for (Eigen::Index i = 0; i < dq.size(); ++i) {
    const double sat = std::clamp(dq[i] * inv_vs, -1.0, 1.0);
    out[i] = friction.viscous[i] * dq[i] + friction.coulomb[i] * sat;
  }
}

void validate_friction(const JointFriction& friction, int n, const std::string& where) {
  auto check = [&](const VectorX& v, const char* name) {
    if (v.size() != n) {
      throw Error(where + ": friction." + name + ": expected " + std::to_string(n) +
                  " values, got " + std::to_string(v.size()));
    }
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(v[i]) || v[i] < 0.0) {
        throw Error(where + ": friction." + name + "[" + std::to_string(i) +
                    "]: expected a finite value >= 0, got " + std::to_string(v[i]));
      }
    }
  };
  check(friction.viscous, "viscous");
  check(friction.coulomb, "coulomb");
  if (!(friction.smoothing_velocity > 0.0) || !std::isfinite(friction.smoothing_velocity)) {
    throw Error(where + ": friction.smoothing_velocity: expected a finite value > 0");
  }
}

}  // namespace extwrench
