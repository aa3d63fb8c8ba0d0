// ModelBuilder::lock_joint: the reduced model of a tree (or of a chain with joints held still),
// built by turning locked joints into fixed ones before the ordinary build.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "builder_messages.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/model/model_builder.hpp"

namespace extwrench {

namespace {

using model_detail::kMinAxisNorm;
using model_detail::num;
using model_detail::prefix;

}  // namespace

void ModelBuilder::lock_joint(std::string name, double value, std::string source) {
  locks_.push_back(Lock{std::move(name), value, std::move(source)});
}

// --- locked joints become fixed ones, their motion at the locked value folded into the origin
void ModelBuilder::apply_locks() {
  for (const Lock& lock : locks_) {
    const std::string where = prefix(lock.source) + "joint '" + lock.joint + "'";
    const auto it = std::find_if(joints_.begin(), joints_.end(),
                                 [&](const JointSpec& j) { return j.name == lock.joint; });
    if (it == joints_.end()) {
      std::string moving;
      for (const JointSpec& j : joints_) {
        if (j.type != JointSpecType::kFixed)
          moving += (moving.empty() ? "'" : ", '") + j.name + "'";
      }
      throw Error(where + ": no such joint in robot '" + name_ +
                  "' (its moving joints: " + (moving.empty() ? "none" : moving) + ")");
    }
    JointSpec& j = *it;
    const std::string at = where + " (" + j.source + ")";
    if (j.type == JointSpecType::kFixed) throw Error(at + ": is already fixed; nothing to lock");
    if (!std::isfinite(lock.value))
      throw Error(at + ": locked value: expected a finite number, got " + num(lock.value));
    if (j.type != JointSpecType::kContinuous && !(lock.value >= j.lower && lock.value <= j.upper)) {
      throw Error(at + ": locked value " + num(lock.value) + " is outside the joint's limits [" +
                  num(j.lower) + ", " + num(j.upper) + "]");
    }
    if (!j.axis.allFinite() || j.axis.norm() < kMinAxisNorm)
      throw Error(at + ": axis: expected a finite, non-zero vector");
    const Vector3 axis = j.axis.normalized();
    Pose motion;
    if (j.type == JointSpecType::kPrismatic) {
      motion.translation = lock.value * axis;
    } else {
      motion.rotation = Eigen::AngleAxisd(lock.value, axis).toRotationMatrix();
    }
    j.origin = j.origin * motion;
    j.type = JointSpecType::kFixed;
  }
}

}  // namespace extwrench
