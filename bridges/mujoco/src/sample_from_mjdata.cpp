// MujocoBridge: mjData -> Sample and the contact truth (docs/mujoco.md "The bridge").
// Conventions: mj_contactForce gives the force geom1 applies to geom2 in the contact frame
// (rows of contact.frame: normal from geom1 to geom2, then the tangents); MuJoCo's <force>/
// <torque> sensors give the wrench the parent applies to the site's body, so the base reading
// is their opposite (tests/reference/test_mjcf.cpp measures both).
#include <mujoco/mujoco.h>

#include <cmath>

#include "extwrench/bridges/mujoco.hpp"
#include "extwrench/core/error.hpp"
#include "mjcf_detail.hpp"

namespace extwrench::mujoco {

namespace mj = mjcf_detail;

namespace {

int sensor_address(const mjModel* m, const std::string& name, int type) {
  if (name.empty()) return -1;
  const int id = mj_name2id(m, mjOBJ_SENSOR, name.c_str());
  if (id < 0) throw Error("MuJoCo bridge: no sensor named '" + name + "'");
  if (m->sensor_type[id] != type || m->sensor_dim[id] != 3) {
    throw Error("MuJoCo bridge: sensor '" + name + "' is not a " +
                (type == mjSENS_FORCE ? "<force>" : "<torque>") + " sensor");
  }
  return m->sensor_adr[id];
}

Vector3 frame_times(const mjtNum* frame, const mjtNum* local) {
  // contact.frame rows are the contact axes in world coordinates: v_W = frameᵀ v_C.
  Vector3 v = Vector3::Zero();
  for (int r = 0; r < 3; ++r) {
    for (int j = 0; j < 3; ++j) v[j] += frame[3 * r + j] * local[r];
  }
  return v;
}

}  // namespace

MujocoBridge::MujocoBridge(const mjModel* m, const Model& model, BridgeOptions options)
    : m_(m), options_(std::move(options)), rng_(options_.seed) {
  const int n = model.nq();
  for (int i = 1; i <= n; ++i) {
    const Joint& joint = model.joints[static_cast<std::size_t>(i)];
    const int j = mj_name2id(m, mjOBJ_JOINT, joint.name.c_str());
    if (j < 0)
      throw Error("MuJoCo bridge: the model's joint '" + joint.name + "' is not in MuJoCo's");
    qpos_adr_.push_back(m->jnt_qposadr[j]);
    dof_adr_.push_back(m->jnt_dofadr[j]);
  }
  body_of_mj_body_.assign(static_cast<std::size_t>(m->nbody), -1);
  for (int b = 1; b < m->nbody; ++b) {
    const auto frame = model.find_frame(mj::body_name(m, b));
    if (frame)
      body_of_mj_body_[static_cast<std::size_t>(b)] =
          model.frames[static_cast<std::size_t>(*frame)].body;
  }
  root_mj_ = mj_name2id(m, mjOBJ_BODY, model.bodies[0].name.c_str());
  force_adr_ = sensor_address(m, options_.force_sensor, mjSENS_FORCE);
  torque_adr_ = sensor_address(m, options_.torque_sensor, mjSENS_TORQUE);
  std::string all_names;
  for (const Body& body : model.bodies) {
    body_names_.push_back(body.name);
    all_names += body.name + "+";
  }
  sample_.q = VectorX::Zero(n);
  sample_.dq = VectorX::Zero(n);
  sample_.tau = VectorX::Zero(n);
  sample_.truth.tau_ext = VectorX::Zero(n);
  sample_.truth.link.reserve(all_names.size());  // every body in contact: no allocation in step
  sample_.has_force = force_adr_ >= 0;
  sample_.has_moment = torque_adr_ >= 0;
  sample_.has_truth = true;
  sample_.has_true_tau_ext = true;
  accumulators_.resize(model.bodies.size());
  contacts_.resize(model.bodies.size());
  jacp_.resize(static_cast<std::size_t>(6 * m->nv));
}

void MujocoBridge::step(const mjData* d) noexcept {
  // Our world is the root body's frame (robot_from_mjmodel); MuJoCo's world maps into it.
  if (root_mj_ > 0) {
    X_root_W_mj_ = mj::pose_from_matrix(d->xpos + 3 * root_mj_, d->xmat + 9 * root_mj_).inverse();
  }
  read_measurements(d);
  read_truth(d);
}

void MujocoBridge::read_measurements(const mjData* d) noexcept {
  sample_.t = d->time;
  const double resolution = options_.encoder_resolution;
  for (std::size_t i = 0; i < qpos_adr_.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    double q = d->qpos[qpos_adr_[i]];
    if (resolution > 0.0) q = resolution * std::round(q / resolution);
    if (options_.position_noise > 0.0) q += options_.position_noise * rng_.normal();
    sample_.q[k] = q;
    sample_.dq[k] = d->qvel[dof_adr_[i]];
    if (options_.velocity_noise > 0.0) sample_.dq[k] += options_.velocity_noise * rng_.normal();
    sample_.tau[k] = d->qfrc_actuator[dof_adr_[i]] + d->qfrc_applied[dof_adr_[i]];
    if (options_.torque_noise > 0.0) sample_.tau[k] += options_.torque_noise * rng_.normal();
  }
  Vector6 reading_S = Vector6::Zero();
  if (force_adr_ >= 0) reading_S.head<3>() = -mj::vec3(d->sensordata + force_adr_);
  if (torque_adr_ >= 0) reading_S.tail<3>() = -mj::vec3(d->sensordata + torque_adr_);
  for (int i = 0; i < 3; ++i) {
    if (options_.force_noise_S > 0.0) reading_S[i] += options_.force_noise_S * rng_.normal();
    if (options_.moment_noise_S > 0.0) reading_S[3 + i] += options_.moment_noise_S * rng_.normal();
  }
  sample_.reading_S = reading_S;
}

// One wrench on MuJoCo body mj_body, MuJoCo world frame: a force at a point and a torque.
void MujocoBridge::add_wrench(int mj_body, const Vector3& force_mj, const Vector3& point_mj,
                              const Vector3& torque_mj, const mjData* d) noexcept {
  const int body = body_of_mj_body_[static_cast<std::size_t>(mj_body)];
  Accumulator& acc = accumulators_[static_cast<std::size_t>(body)];
  const Vector3 force_W = X_root_W_mj_.rotation * force_mj;
  const Vector3 point_W = X_root_W_mj_.act(point_mj);
  const double weight = force_W.norm() + 1e-300;  // a zero force still places its point
  ++acc.points;
  acc.force += force_W;
  acc.moment_O += point_W.cross(force_W) + X_root_W_mj_.rotation * torque_mj;
  acc.weighted_point += weight * point_W;
  acc.weight += weight;
  // τ_ext = Jᵀ f at the point (MuJoCo's own Jacobian), in our joint order.
  mjtNum* jacp = jacp_.data();
  mjtNum* jacr = jacp_.data() + 3 * m_->nv;
  mj_jac(m_, d, jacp, jacr, point_mj.data(), mj_body);
  for (std::size_t i = 0; i < dof_adr_.size(); ++i) {
    double tau = 0.0;
    for (int r = 0; r < 3; ++r) {
      tau += jacp[r * m_->nv + dof_adr_[i]] * force_mj[r] +
             jacr[r * m_->nv + dof_adr_[i]] * torque_mj[r];
    }
    sample_.truth.tau_ext[static_cast<Eigen::Index>(i)] += tau;
  }
}

void MujocoBridge::read_truth(const mjData* d) noexcept {
  for (Accumulator& acc : accumulators_) acc = Accumulator{};
  sample_.truth.tau_ext.setZero();
  for (int c = 0; c < d->ncon; ++c) {
    const mjContact& contact = d->contact[c];
    if (contact.efc_address < 0) continue;  // excluded: no force
    const int b1 = m_->geom_bodyid[contact.geom1], b2 = m_->geom_bodyid[contact.geom2];
    const bool robot1 = body_of_mj_body_[static_cast<std::size_t>(b1)] >= 0;
    const bool robot2 = body_of_mj_body_[static_cast<std::size_t>(b2)] >= 0;
    if (robot1 == robot2) continue;  // the world's own, or the robot's with itself (internal)
    mjtNum local[6];
    mj_contactForce(m_, d, c, local);
    // On geom2 as computed; on geom1 its opposite.
    const double sign = robot2 ? 1.0 : -1.0;
    const Vector3 force_mj = sign * frame_times(contact.frame, local);
    const Vector3 torque_mj = sign * frame_times(contact.frame, local + 3);
    add_wrench(robot2 ? b2 : b1, force_mj, mj::vec3(contact.pos), torque_mj, d);
  }
  for (int b = 1; b < m_->nbody; ++b) {
    if (body_of_mj_body_[static_cast<std::size_t>(b)] < 0) continue;
    const mjtNum* w = d->xfrc_applied + 6 * b;
    if (w[0] == 0 && w[1] == 0 && w[2] == 0 && w[3] == 0 && w[4] == 0 && w[5] == 0) continue;
    add_wrench(b, mj::vec3(w), mj::vec3(d->xipos + 3 * b), mj::vec3(w + 3), d);
  }
  finish_truth();
}

// Per body: the resultant, its line of action (central axis) and on it the point nearest to
// the force-weighted mean c of the contact points: p = c + F × M_c / |F|², leaving the pure
// moment M_c − (p − c) × F, along F (zero for one point contact without torsion).
void MujocoBridge::finish_truth() noexcept {
  num_contacts_ = 0;
  Truth& truth = sample_.truth;
  truth.link.clear();
  truth.body = -1;
  Vector3 force_W = Vector3::Zero(), moment_W = Vector3::Zero(), point_W = Vector3::Zero();
  for (std::size_t b = 0; b < accumulators_.size(); ++b) {
    const Accumulator& acc = accumulators_[b];
    if (acc.points == 0) continue;
    BodyContactTruth& out = contacts_[static_cast<std::size_t>(num_contacts_++)];
    const Vector3 c = acc.weighted_point / acc.weight;
    const Vector3 moment_c = acc.moment_O - c.cross(acc.force);
    const double f2 = acc.force.squaredNorm();
    out.body = static_cast<int>(b);
    out.points = acc.points;
    out.force_W = acc.force;
    out.point_W = f2 > 0.0 ? Vector3(c + acc.force.cross(moment_c) / f2) : c;
    out.moment_W = moment_c - (out.point_W - c).cross(acc.force);
    if (truth.body < 0) {
      truth.body = out.body;
      point_W = out.point_W;
    } else {
      truth.link += '+';
    }
    truth.link += body_names_[b];  // capacity reserved at set-up
    force_W += out.force_W;
    moment_W += out.moment_W;
  }
  truth.contacts = num_contacts_;
  truth.force_W = force_W;
  truth.moment_W = moment_W;
  truth.point_W = point_W;
}

}  // namespace extwrench::mujoco
