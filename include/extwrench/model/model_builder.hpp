// Builds a validated Model from URDF-like links and joints (tree, fixed joints allowed).
// Parsers (io/) fill the specs; every spec carries a `source` string ("file.urdf:42") that
// each error message starts with, so errors name the file and line of the offending element.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "extwrench/model/model.hpp"

namespace extwrench {

struct LinkSpec {
  std::string name;
  Inertia inertia;     ///< in the link frame (URDF <inertial> already applied)
  std::string source;  ///< where it was defined, for error messages, e.g. "robot.urdf:12"
  /// Where the mass properties were given (e.g. the <inertia> element); empty: `source`.
  std::string inertia_source;
};

enum class JointSpecType { kRevolute, kContinuous, kPrismatic, kFixed };

struct JointSpec {
  std::string name;
  JointSpecType type = JointSpecType::kRevolute;
  std::string parent;               ///< parent link name
  std::string child;                ///< child link name
  Pose origin;                      ///< X_{parent link, child link} at q = 0
  Vector3 axis = Vector3::UnitX();  ///< URDF default axis (1, 0, 0); need not be unit, not zero
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  double velocity_limit = std::numeric_limits<double>::infinity();
  double effort_limit = std::numeric_limits<double>::infinity();
  double damping = 0.0;
  double friction = 0.0;
  double armature = 0.0;  ///< reflected rotor inertia [kg m^2 | kg], Joint::armature
  std::string source;
};

/// Extra named frame attached to a link (e.g. a DH frame or a tool point).
struct FrameSpec {
  std::string name;
  std::string link;
  Pose placement;  ///< X_{link, frame}
  std::string source;
};

/// Most links (and so joints) a model may have (docs/model.md "Limits"); building is linear in
/// them, a larger description is refused before any work.
inline constexpr std::size_t kMaxLinks = 100'000;

class ModelBuilder {
 public:
  void set_name(std::string name) { name_ = std::move(name); }
  void set_gravity(const Vector3& g) { gravity_ = g; }
  void add_link(LinkSpec link) { links_.push_back(std::move(link)); }
  void add_joint(JointSpec joint) { joints_.push_back(std::move(joint)); }
  void add_frame(FrameSpec frame) { frames_.push_back(std::move(frame)); }
  /// Locks the moving joint `name` at `value` [rad | m] (like Pinocchio's buildReducedModel):
  /// build() turns it into a fixed joint whose origin includes that motion, so its child link
  /// merges into the parent body, inertia composed, frames and collision shapes carried over.
  /// build() throws, prefixed by `source` (e.g. "--lock" or "config.yaml:3: locked_joints"),
  /// for an unknown or fixed joint, a non-finite value or one outside the joint's limits.
  void lock_joint(std::string name, double value, std::string source);

  /// Validates everything (see validate_inertia and docs/model.md) and builds the Model:
  /// fixed joints merged into the parent body, bodies in topological (depth-first) order,
  /// a Frame for every link. Throws extwrench::Error naming source, element and field.
  [[nodiscard]] Model build() const;

 private:
  // The steps of build, in order; each throws at the first bad element it meets.
  struct Topology;  // links by name, each link's parent and child joints (model_builder.cpp)
  [[nodiscard]] Topology index_links() const;
  void connect_joints(Topology& topology) const;
  [[nodiscard]] int find_root(const Topology& topology) const;
  [[nodiscard]] Model traverse(const Topology& topology, int root,
                               std::vector<std::string>& body_source) const;
  void add_extra_frames(Model& model) const;
  static void check_massless_bodies(const Model& model,
                                    const std::vector<std::string>& body_source);
  [[nodiscard]] std::string cycle_message(const Topology& topology, int start) const;
  void apply_locks();

  struct Lock {
    std::string joint;
    double value = 0.0;
    std::string source;
  };

  std::string name_;
  Vector3 gravity_{0.0, 0.0, -9.81};
  std::vector<LinkSpec> links_;
  std::vector<JointSpec> joints_;
  std::vector<FrameSpec> frames_;
  std::vector<Lock> locks_;
};

/// Throws extwrench::Error (prefixed by `where`) when mass properties are not physical:
/// non-finite entries, negative mass, non-symmetric or not positive semi-definite inertia,
/// or principal moments violating the triangle inequality.
void validate_inertia(const Inertia& inertia, const std::string& where);

/// Checks a built model: finite numbers, unit axes, limits, and that the joint-space mass
/// matrix is positive definite at q = 0 (zero-mass bodies are fine only then).
void validate_model(const Model& model);

}  // namespace extwrench
