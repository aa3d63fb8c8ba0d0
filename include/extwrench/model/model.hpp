// The constant robot model: bodies, joints, frames, gravity. Built and validated by
// ModelBuilder (model_builder.hpp); never modified by the algorithms, which write into a
// dynamics::Data workspace instead (Pinocchio's Model/Data split).
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "extwrench/core/types.hpp"

namespace extwrench {

/// Joint types kept in a Model. URDF `continuous` becomes kRevolute without limits; `fixed`
/// joints are merged into their parent body by the builder and never appear here.
enum class JointType { kRevolute, kPrismatic };

/// Mass properties of a rigid body, in the body frame.
struct Inertia {
  double mass = 0.0;                      ///< [kg]
  Vector3 com = Vector3::Zero();          ///< centre of mass in the body frame [m]
  Matrix3 inertia_com = Matrix3::Zero();  ///< rotational inertia about the CoM, body axes [kg m^2]

  /// Sum of two bodies' mass properties expressed in the same frame.
  Inertia operator+(const Inertia& other) const;
  /// The same mass properties seen from frame A, when this is given in frame B: X = X_AB.
  Inertia transformed(const Pose& X_AB) const;
};

/// The joint that moves body i with respect to its parent body. Body i's frame is the joint
/// frame after the motion: X_{parent,i}(q) = placement * motion(axis, q), as in URDF.
struct Joint {
  std::string name;
  JointType type = JointType::kRevolute;
  Pose placement;                   ///< X_{parent body, joint frame} at q = 0
  Vector3 axis = Vector3::UnitZ();  ///< unit axis in the joint (= child body) frame
  double lower = -std::numeric_limits<double>::infinity();  ///< position limit [rad | m]
  double upper = std::numeric_limits<double>::infinity();
  double velocity_limit = std::numeric_limits<double>::infinity();
  double effort_limit = std::numeric_limits<double>::infinity();
  double damping = 0.0;   ///< viscous friction [N m s/rad | N s/m] (URDF <dynamics>)
  double friction = 0.0;  ///< Coulomb friction [N m | N] (URDF <dynamics>)
  /// Armature: the motor's rotor inertia reflected through the gears, r^2 I_rotor
  /// [kg m^2 | kg] (URDF <dynamics armature>, docs/model.md "Armature"). It adds to B's
  /// diagonal only (B_ii += armature, tau_i += armature q_ddot_i), as MuJoCo's joint armature and
  /// KDL's joint inertia; the base reading does not see it (docs/model.md).
  double armature = 0.0;
};

/// A body: one or more URDF links welded together by fixed joints.
struct Body {
  std::string name;  ///< name of the first (moving) link of the body
  Inertia inertia;   ///< merged mass properties in the body frame
};

/// A named frame rigidly attached to a body: every URDF link (merged ones too), DH frames,
/// sensor or tool frames.
struct Frame {
  std::string name;
  int body = 0;    ///< index of the body it is attached to
  Pose placement;  ///< X_{body, frame}
};

/// Constant description of a fixed-base kinematic tree with 1-DoF joints.
///
/// Indexing follows the paper: body 0 is link 0 (fixed to the base sensor / ground); body i
/// (1 <= i <= n) is moved by joint i, whose coordinate is q[i - 1]. Bodies are in topological
/// order: parent(i) < i. A serial chain has parent(i) = i - 1.
struct Model {
  std::string name;
  std::vector<Body> bodies;          ///< size n + 1
  std::vector<Joint> joints;         ///< size n + 1; joints[0] is unused (the root has no joint)
  std::vector<int> parents;          ///< size n + 1; parents[0] = -1
  std::vector<Frame> frames;         ///< every named frame, one per URDF link at least
  Vector3 gravity{0.0, 0.0, -9.81};  ///< gravity acceleration in the root (world) frame [m/s^2]

  /// Number of joint coordinates n (= number of moving bodies).
  [[nodiscard]] int nq() const { return static_cast<int>(bodies.size()) - 1; }
  [[nodiscard]] int num_bodies() const { return static_cast<int>(bodies.size()); }
  /// True when parents[i] == i - 1 for every body: the estimators of Table I need this.
  [[nodiscard]] bool is_serial_chain() const;
  /// True when some joint has a non-zero armature (the algorithms skip its O(n) terms otherwise,
  /// so that a model without one computes bit for bit what it did before armature existed).
  [[nodiscard]] bool has_armature() const;
  /// Total mass of all bodies, link 0 included [kg].
  [[nodiscard]] double total_mass() const;

  /// Index of the body of that name, or of the body a frame of that name is attached to.
  [[nodiscard]] std::optional<int> find_body(std::string_view name) const;
  [[nodiscard]] std::optional<int> find_frame(std::string_view name) const;
  [[nodiscard]] std::optional<int> find_joint(std::string_view name) const;
  /// As find_*, but throws extwrench::Error naming the missing entry.
  [[nodiscard]] int body_index(std::string_view name) const;
  [[nodiscard]] int frame_index(std::string_view name) const;

  /// True when body `ancestor` is on the path from the root to `body` (a body is its own ancestor).
  [[nodiscard]] bool is_ancestor(int ancestor, int body) const;
};

/// Where the model branches, for the "not a serial chain" message: for each body with more than
/// one child, the joints of each branch (e.g. "body 'hand': branch 'finger_1', branch
/// 'finger_2'"); empty for a serial chain.
[[nodiscard]] std::string describe_branches(const Model& model);

}  // namespace extwrench
