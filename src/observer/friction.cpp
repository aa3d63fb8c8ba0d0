#include "extwrench/observer/friction.hpp"

#include <algorithm>
#include <cmath>
#include <string>

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
         (coulomb.size() == 0 || coulomb.isZero(0.0)) && (offset.size() == 0 || offset.isZero(0.0));
}

std::string_view to_string(SmoothSign s) noexcept {
  switch (s) {
    case SmoothSign::kTanh:
      return "tanh";
    case SmoothSign::kSigmoid:
      return "sigmoid";
    case SmoothSign::kDahl:
      return "dahl";
    case SmoothSign::kSaturation:
      break;
  }
  return "saturation";
}

double smooth_sign(SmoothSign sign, double dq, double smoothing, double shift) noexcept {
  switch (sign) {
    case SmoothSign::kTanh:
      return std::tanh(dq / smoothing);
    case SmoothSign::kSigmoid:
      return std::tanh((dq + shift) / smoothing) - std::tanh(shift / smoothing);
    case SmoothSign::kDahl:
      return dq > 0.0 ? 1.0 : (dq < 0.0 ? -1.0 : 0.0);
    case SmoothSign::kSaturation:
      break;
  }
  return std::clamp(dq / smoothing, -1.0, 1.0);
}

double dahl_step(double z, double displacement, double presliding) noexcept {
  if (displacement == 0.0) return z;
  const double s = displacement > 0.0 ? 1.0 : -1.0;
  return s + (z - s) * std::exp(-std::abs(displacement) / presliding);
}

double smooth_sign(const JointFriction& friction, Eigen::Index i, double dq) noexcept {
  const double shift = friction.velocity_shift.size() > 0 ? friction.velocity_shift[i] : 0.0;
  return smooth_sign(friction.sign, dq, friction.smoothing(i), shift);
}

namespace {

// D_i q̇ + F_c,i s + o_i of joint i, for the Coulomb sign s.
double joint_friction(const JointFriction& friction, Eigen::Index i, double dq,
                      double sign) noexcept {
  const double offset = friction.offset.size() > 0 ? friction.offset[i] : 0.0;
  return friction.viscous[i] * dq + friction.coulomb[i] * sign + offset;
}

}  // namespace

void friction_torque(const JointFriction& friction, const Eigen::Ref<const VectorX>& dq,
                     Eigen::Ref<VectorX> out) noexcept {
  const bool plain = friction.sign == SmoothSign::kSaturation && friction.offset.size() == 0 &&
                     friction.joint_smoothing.size() == 0;
  if (plain) {  // the URDF model: kept as it was, bit for bit
    const double inv_vs = 1.0 / friction.smoothing_velocity;
    for (Eigen::Index i = 0; i < dq.size(); ++i) {
      const double sat = std::clamp(dq[i] * inv_vs, -1.0, 1.0);
      out[i] = friction.viscous[i] * dq[i] + friction.coulomb[i] * sat;
    }
    return;
  }
  for (Eigen::Index i = 0; i < dq.size(); ++i)
    out[i] = joint_friction(friction, i, dq[i], smooth_sign(friction, i, dq[i]));
}

void friction_torque(const JointFriction& friction, const Eigen::Ref<const VectorX>& dq,
                     const Eigen::Ref<const VectorX>& presliding_state,
                     Eigen::Ref<VectorX> out) noexcept {
  if (friction.sign != SmoothSign::kDahl) {
    friction_torque(friction, dq, out);
    return;
  }
  for (Eigen::Index i = 0; i < dq.size(); ++i)
    out[i] = joint_friction(friction, i, dq[i], presliding_state[i]);
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
  auto check_optional = [&](const VectorX& v, const char* name, bool positive) {
    if (v.size() != 0 && v.size() != n) {
      throw Error(where + ": friction." + name + ": expected 0 or " + std::to_string(n) +
                  " values, got " + std::to_string(v.size()));
    }
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      if (!std::isfinite(v[i]) || (positive && !(v[i] > 0.0))) {
        throw Error(where + ": friction." + name + "[" + std::to_string(i) +
                    "]: expected a finite " + (positive ? "value > 0" : "value") + ", got " +
                    std::to_string(v[i]));
      }
    }
  };
  check_optional(friction.offset, "offset", false);
  check_optional(friction.joint_smoothing, "smoothing_velocity", true);
  check_optional(friction.velocity_shift, "velocity_shift", false);
  check_optional(friction.presliding, "presliding_displacement", true);
  const bool dahl = friction.sign == SmoothSign::kDahl;
  if (dahl && friction.presliding.size() != n) {
    throw Error(where + ": friction.presliding_displacement: expected " + std::to_string(n) +
                " values > 0 with sign: dahl, got " + std::to_string(friction.presliding.size()));
  }
  if (!dahl && friction.presliding.size() != 0) {
    throw Error(where +
                ": friction.presliding_displacement: only used with sign: dahl, got sign: " +
                std::string(to_string(friction.sign)));
  }
  if (!(friction.smoothing_velocity > 0.0) || !std::isfinite(friction.smoothing_velocity)) {
    throw Error(where + ": friction.smoothing_velocity: expected a finite value > 0");
  }
}

}  // namespace extwrench
