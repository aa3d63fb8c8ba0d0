// Reference values computed by orocos KDL from a URDF it parses itself (kdl_parser): joint
// torques with external wrenches (ChainIdSolver_RNE) and the base reading, obtained from six
// virtual joints (3 prismatic, 3 revolute, at the world origin, q = 0) prepended to the chain:
// their torques are the wrench the ground applies to link 0. Nothing here uses our Jacobian,
// RNEA or kinematics.
#pragma once

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <memory>
#include <stdexcept>

#include "support/test_robots.hpp"

namespace extwrench::test {

class KdlReference {
 public:
  explicit KdlReference(const Model& model) : n_(model.nq()) {
    KDL::Tree tree;
    if (!kdl_parser::treeFromString(model_to_urdf(model), tree))
      throw std::runtime_error("kdl_parser failed");
    KDL::Chain arm;
    if (!tree.getChain(model.bodies.front().name, model.bodies.back().name, arm)) {
      throw std::runtime_error("KDL getChain failed");
    }
    const Inertia& in0 = model.bodies[0].inertia;
    const Matrix3& I = in0.inertia_com;
    const KDL::RigidBodyInertia link0(
        in0.mass, KDL::Vector(in0.com.x(), in0.com.y(), in0.com.z()),
        KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
    const KDL::Joint::JointType types[6] = {KDL::Joint::TransX, KDL::Joint::TransY,
                                            KDL::Joint::TransZ, KDL::Joint::RotX,
                                            KDL::Joint::RotY,   KDL::Joint::RotZ};
    for (int k = 0; k < 6; ++k) {
      chain_.addSegment(KDL::Segment("virtual" + std::to_string(k), KDL::Joint(types[k]),
                                     KDL::Frame::Identity(),
                                     k == 5 ? link0 : KDL::RigidBodyInertia::Zero()));
    }
    chain_.addChain(arm);
    const Vector3& g = model.gravity;
    id_ = std::make_unique<KDL::ChainIdSolver_RNE>(chain_, KDL::Vector(g.x(), g.y(), g.z()));
    fk_ = std::make_unique<KDL::ChainFkSolverPos_recursive>(chain_);
  }

  /// Pose of body `body` (0 = link 0) in the world, from KDL's forward kinematics.
  Pose compute_body_pose(const VectorX& q, int body) {
    KDL::Frame f;
    fk_->JntToCart(full(q), f, 6 + body);
    Pose X;
    for (int r = 0; r < 3; ++r) {
      X.translation[r] = f.p(r);
      for (int c = 0; c < 3; ++c) X.rotation(r, c) = f.M(r, c);
    }
    return X;
  }

  struct Result {
    VectorX tau;      ///< joint torques needed with the wrench (n)
    VectorX tau_ext;  ///< J_pᵀ W_ext = τ(no wrench) − τ(wrench) (n)
    Vector6
        reading_W;  ///< [f_m; n_m]: what the robot discharges, world axes, moment about the origin
  };

  /// F_W at p_W and the pure moment M_W (world) on body `body`, at (q, q̇, q̈).
  Result compute(const VectorX& q, const VectorX& dq, const VectorX& ddq, int body,
                 const Vector3& F_W, const Vector3& p_W, const Vector3& M_W) {
    const Pose X = compute_body_pose(q, body);
    // KDL wants the wrench on segment `body` in that segment's frame, about its origin.
    const Vector3 F_L = X.rotation.transpose() * F_W;
    const Vector3 M_L = X.rotation.transpose() * (M_W + (p_W - X.translation).cross(F_W));
    KDL::Wrenches with(chain_.getNrOfSegments(), KDL::Wrench::Zero()), none = with;
    with[5 + body] =
        KDL::Wrench(KDL::Vector(F_L.x(), F_L.y(), F_L.z()), KDL::Vector(M_L.x(), M_L.y(), M_L.z()));
    KDL::JntArray t_with(6 + n_), t_none(6 + n_);
    id_->CartToJnt(full(q), full(dq), full(ddq), with, t_with);
    id_->CartToJnt(full(q), full(dq), full(ddq), none, t_none);
    Result r;
    r.tau.resize(n_);
    r.tau_ext.resize(n_);
    for (int i = 0; i < n_; ++i) {
      r.tau[i] = t_with(6 + i);
      r.tau_ext[i] = t_none(6 + i) - t_with(6 + i);
    }
    // Virtual joint torques = wrench the ground applies to link 0 (f_0, n_0 about the origin);
    // the sensor reads what the robot discharges: the opposite.
    for (int k = 0; k < 6; ++k) r.reading_W[k] = -t_with(k);
    return r;
  }

 private:
  KDL::JntArray full(const VectorX& v) const {
    KDL::JntArray a(6 + n_);
    for (int i = 0; i < n_; ++i) a(6 + i) = v[i];
    return a;
  }
  int n_;
  KDL::Chain chain_;
  std::unique_ptr<KDL::ChainIdSolver_RNE> id_;
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk_;
};

/// A world-frame reading [f; n about the origin] seen by a sensor at X_WS: sensor axes, moment
/// about the sensor origin.
inline Vector6 to_sensor_frame(const Vector6& reading_W, const Pose& X_WS) {
  const Vector3 f = reading_W.head<3>();
  const Vector3 n_s = reading_W.tail<3>() - X_WS.translation.cross(f);
  Vector6 out;
  out << X_WS.rotation.transpose() * f, X_WS.rotation.transpose() * n_s;
  return out;
}

}  // namespace extwrench::test
