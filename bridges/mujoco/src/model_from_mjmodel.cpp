// A compiled mjModel -> ModelBuilder specs, sites as frames, collision geoms as shapes.
// MuJoCo's kinematics (mj_kinematics): body b's pose is its parent's times (body_pos, body_quat)
// times, for each of its joints in order, T(jnt_pos) R(jnt_axis, qpos - qpos0) T(-jnt_pos).
// Each joint becomes one JointSpec whose child is the joint's anchor frame; a body whose last
// anchor is off its origin hangs from that anchor by a fixed joint, which the builder merges.
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/model/model_builder.hpp"
#include "mjcf_detail.hpp"

namespace extwrench::mujoco {

namespace mj = mjcf_detail;

namespace {

// "file: body 'link3'"
std::string body_where(const mjModel* m, const std::string& file, int b) {
  return file + ": body '" + mj::body_name(m, b) + "'";
}

// A robot candidate: its subtree has hinge or slide joints and the body itself is not free
// (a free body is an object of the scene).
bool is_robot_candidate(const mjModel* m, int top) {
  bool has_joints = false;
  for (int b = top; b < m->nbody; ++b) {
    if (!mj::is_in_subtree(m, top, b)) continue;
    for (int k = 0; k < m->body_jntnum[b]; ++k) {
      const int type = m->jnt_type[m->body_jntadr[b] + k];
      if (b == top && type == mjJNT_FREE) return false;
      has_joints = has_joints || type == mjJNT_HINGE || type == mjJNT_SLIDE;
    }
  }
  return has_joints;
}

int choose_root(const mjModel* m, const std::string& file, const LoadOptions& options) {
  if (!options.root_body.empty()) {
    const int b = mj_name2id(m, mjOBJ_BODY, options.root_body.c_str());
    if (b < 0) {
      throw Error(file + ": root_body '" + options.root_body +
                  "': no body of that name (top-level bodies: " + mj::top_level_names(m) + ")");
    }
    return b;
  }
  std::vector<int> candidates, top_level;
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_parentid[b] != 0) continue;
    top_level.push_back(b);
    if (is_robot_candidate(m, b)) candidates.push_back(b);
  }
  if (candidates.size() == 1) return candidates[0];
  if (candidates.empty() && top_level.size() == 1) return top_level[0];
  if (top_level.empty()) throw Error(file + ": <worldbody> holds no body: no robot to load");
  throw Error(file + ": " + std::to_string(candidates.size()) +
              " top-level bodies are jointed robots (top-level bodies: " + mj::top_level_names(m) +
              "): choose one with root_body (--root-body BODY)");
}

// Bodies kept: the root's subtree, or only the path root -> tip and what is welded to the tip
// (a hand on the flange: its mass moves with the tip; bodies beyond a joint are dropped).
std::vector<bool> kept_bodies(const mjModel* m, const std::string& file, int root,
                              const LoadOptions& options) {
  std::vector<bool> keep(static_cast<std::size_t>(m->nbody), false);
  if (options.tip_body.empty()) {
    for (int b = 0; b < m->nbody; ++b)
      keep[static_cast<std::size_t>(b)] = mj::is_in_subtree(m, root, b);
    return keep;
  }
  const int tip = mj_name2id(m, mjOBJ_BODY, options.tip_body.c_str());
  if (tip < 0) throw Error(file + ": tip_body '" + options.tip_body + "': no body of that name");
  if (!mj::is_in_subtree(m, root, tip)) {
    throw Error(body_where(m, file, tip) + ": tip_body is not in the subtree of the root body '" +
                mj::body_name(m, root) + "'");
  }
  for (int b = tip;; b = m->body_parentid[b]) {
    keep[static_cast<std::size_t>(b)] = true;
    if (b == root) break;
  }
  for (int b = 0; b < m->nbody; ++b) {
    if (b == tip || !mj::is_in_subtree(m, tip, b)) continue;
    bool welded = true;
    for (int a = b; a != tip; a = m->body_parentid[a]) welded = welded && m->body_jntnum[a] == 0;
    keep[static_cast<std::size_t>(b)] = welded;
  }
  return keep;
}

// X_{world, root} at qpos0; the root must not move with respect to the world.
Pose root_pose_in_world(const mjModel* m, const std::string& file, int root) {
  Pose X_W_root = Pose::identity();
  for (int b = m->body_parentid[root]; b > 0; b = m->body_parentid[b]) {
    if (m->body_jntnum[b] > 0) {
      throw Error(body_where(m, file, root) +
                  ": root_body moves with respect to the world (body '" + mj::body_name(m, b) +
                  "' above it has joints): choose a welded root");
    }
  }
  for (int b = root; b > 0; b = m->body_parentid[b]) X_W_root = mj::body_offset(m, b) * X_W_root;
  return X_W_root;
}

double effort_limit(const mjModel* m, int joint) {
  double limit = std::numeric_limits<double>::infinity();
  for (int u = 0; u < m->nu; ++u) {
    if (m->actuator_trntype[u] != mjTRN_JOINT || m->actuator_trnid[2 * u] != joint) continue;
    const double gear = std::abs(m->actuator_gear[6 * u]);
    double actuator = std::numeric_limits<double>::infinity();
    if (m->actuator_forcelimited[u]) {
      actuator = std::max(std::abs(m->actuator_forcerange[2 * u]),
                          std::abs(m->actuator_forcerange[2 * u + 1]));
    } else if (m->actuator_gaintype[u] == mjGAIN_FIXED && m->actuator_biastype[u] == mjBIAS_NONE &&
               m->actuator_ctrllimited[u]) {
      // A motor: force = gain * ctrl.
      actuator = std::abs(m->actuator_gainprm[mjNGAIN * u]) *
                 std::max(std::abs(m->actuator_ctrlrange[2 * u]),
                          std::abs(m->actuator_ctrlrange[2 * u + 1]));
    }
    limit = std::min(limit, gear * actuator);
  }
  return limit;
}

JointSpec joint_spec(const mjModel* m, const std::string& file, int b, int j) {
  JointSpec spec;
  spec.name = mj::joint_name(m, j);
  spec.source = file + ": joint '" + spec.name + "' of body '" + mj::body_name(m, b) + "'";
  const int type = m->jnt_type[j];
  if (type != mjJNT_HINGE && type != mjJNT_SLIDE) {
    throw Error(spec.source + ": unsupported joint type '" + mj::joint_type_name(type) +
                "' (only hinge and slide joints; the root must be welded to the world)");
  }
  if (m->jnt_stiffness[j] != 0.0) {
    throw Error(spec.source + ": attribute 'stiffness': joint springs are not modelled, got " +
                std::to_string(m->jnt_stiffness[j]));
  }
  const bool limited = m->jnt_limited[j] != 0;
  spec.type = type == mjJNT_SLIDE ? JointSpecType::kPrismatic
              : limited           ? JointSpecType::kRevolute
                                  : JointSpecType::kContinuous;
  spec.axis = mj::vec3(m->jnt_axis + 3 * j);
  if (limited) {
    spec.lower = m->jnt_range[2 * j];
    spec.upper = m->jnt_range[2 * j + 1];
  }
  const int dof = m->jnt_dofadr[j];
  spec.damping = m->dof_damping[dof];
  spec.friction = m->dof_frictionloss[dof];
  spec.armature = m->dof_armature[dof];
  spec.effort_limit = effort_limit(m, j);
  return spec;
}

// The motion at q = qpos0 is the identity in MuJoCo: R(axis, -qpos0) (or a shift) folded into
// the origin makes our q equal to MuJoCo's qpos.
Pose reference_offset(const mjModel* m, int j) {
  const double ref = m->qpos0[m->jnt_qposadr[j]];
  const Vector3 axis = mj::vec3(m->jnt_axis + 3 * j).normalized();
  Pose X;
  if (m->jnt_type[j] == mjJNT_HINGE) {
    X.rotation = Eigen::AngleAxisd(-ref, axis).toRotationMatrix();
  } else {
    X.translation = -ref * axis;
  }
  return X;
}

Pose translation(const Vector3& p) {
  Pose X;
  X.translation = p;
  return X;
}

JointSpec fixed_joint(std::string name, std::string parent, std::string child, const Pose& origin,
                      std::string source) {
  JointSpec joint;
  joint.name = std::move(name);
  joint.type = JointSpecType::kFixed;
  joint.parent = std::move(parent);
  joint.child = std::move(child);
  joint.origin = origin;
  joint.source = std::move(source);
  return joint;
}

// The joints (or the weld) from `parent_link` to body b's link, as MuJoCo composes them.
void add_body_joints(const mjModel* m, const std::string& file, int b,
                     const std::string& parent_link, const Pose& X_parent_body,
                     ModelBuilder& builder) {
  const std::string name = mj::body_name(m, b);
  const int first = m->body_jntadr[b], count = m->body_jntnum[b];
  if (count == 0) {
    builder.add_joint(
        fixed_joint(name + "/weld", parent_link, name, X_parent_body, body_where(m, file, b)));
    return;
  }
  std::string previous_link = parent_link;
  Pose X_previous_anchor = X_parent_body;  // from the previous link to the body frame
  for (int k = 0; k < count; ++k) {
    const int j = first + k;
    JointSpec spec = joint_spec(m, file, b, j);
    const Vector3 anchor = mj::vec3(m->jnt_pos + 3 * j);
    const bool last_on_origin = k + 1 == count && anchor.isZero(0.0);
    spec.parent = previous_link;
    spec.child = last_on_origin ? name : name + "/" + spec.name;
    spec.origin = X_previous_anchor * translation(anchor) * reference_offset(m, j);
    X_previous_anchor = translation(-anchor);
    previous_link = spec.child;
    if (!last_on_origin) {
      builder.add_link(LinkSpec{spec.child, Inertia{}, spec.source, {}});
    }
    builder.add_joint(std::move(spec));
  }
  if (previous_link != name) {
    builder.add_joint(fixed_joint(name + "/anchor", previous_link, name, X_previous_anchor,
                                  body_where(m, file, b)));
  }
}

// MuJoCo's compiled mass properties: body_ipos, and body_inertia about principal axes body_iquat.
Inertia body_inertia(const mjModel* m, int b) {
  Inertia inertia;
  inertia.mass = m->body_mass[b];
  inertia.com = mj::vec3(m->body_ipos + 3 * b);
  const Matrix3 R = mj::quat_rotation(m->body_iquat + 4 * b);
  inertia.inertia_com = R * mj::vec3(m->body_inertia + 3 * b).asDiagonal() * R.transpose();
  return inertia;
}

void add_sites(const mjModel* m, const std::string& file, int b, ModelBuilder& builder) {
  for (int s = 0; s < m->nsite; ++s) {
    const char* site = mj_id2name(m, mjOBJ_SITE, s);
    if (m->site_bodyid[s] != b || site == nullptr) continue;
    builder.add_frame(
        FrameSpec{site, mj::body_name(m, b), mj::pose(m->site_pos + 3 * s, m->site_quat + 4 * s),
                  file + ": site '" + site + "' of body '" + mj::body_name(m, b) + "'"});
  }
}

}  // namespace

RobotDescription robot_from_mjmodel(const mjModel* m, const std::string& file,
                                    const LoadOptions& options) {
  const int root = choose_root(m, file, options);
  const std::vector<bool> keep = kept_bodies(m, file, root, options);
  const Pose X_W_root = root == 0 ? Pose::identity() : root_pose_in_world(m, file, root);
  ModelBuilder builder;
  builder.set_name(mj::model_name(m));
  // Link 0 is the root body when it is welded to the world, else a massless "world" link.
  const bool root_moves = root != 0 && m->body_jntnum[root] > 0;
  const Vector3 gravity_W = mj::vec3(m->opt.gravity);
  if (root_moves) {
    builder.add_link(LinkSpec{"world", Inertia{}, file + ": the world", {}});
    builder.set_gravity(options.gravity.value_or(gravity_W));
  } else {
    // The root frame is the model's world frame (docs/conventions.md).
    builder.set_gravity(options.gravity.value_or(X_W_root.rotation.transpose() * gravity_W));
  }
  std::vector<mj::GeomSpec> geoms;
  for (int b = root; b < m->nbody; ++b) {
    if (!keep[static_cast<std::size_t>(b)]) continue;
    const std::string where = body_where(m, file, b);
    builder.add_link(LinkSpec{mj::body_name(m, b), body_inertia(m, b), where,
                              where + ": <inertial> (compiled mass, ipos, inertia)"});
    if (b != root) {
      add_body_joints(m, file, b, mj::body_name(m, m->body_parentid[b]), mj::body_offset(m, b),
                      builder);
    } else if (root_moves) {
      add_body_joints(m, file, b, "world", X_W_root, builder);
    }
    add_sites(m, file, b, builder);
    mj::collect_geoms(m, file, b, geoms);
  }
  lock_joints(options, builder);
  RobotDescription robot;
  robot.model = builder.build();
  robot.geometry = mj::build_geometry(m, robot.model, geoms, options);
  robot.source = file;
  return robot;
}

}  // namespace extwrench::mujoco
