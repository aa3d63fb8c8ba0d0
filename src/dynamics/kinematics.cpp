#include "extwrench/dynamics/kinematics.hpp"

#include "spatial.hpp"

namespace extwrench {

void forward_kinematics(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  const int nb = model.num_bodies();
  data.X_WB[0] = Pose{};
  data.S[0].setZero();
  for (int i = 0; i < nb; ++i) {
    if (i > 0) {
      const Joint& joint = model.joints[i];
      const Pose& X_WP = data.X_WB[model.parents[i]];
      Pose& X_WB = data.X_WB[i];
      const Matrix3 R_WJ = X_WP.rotation * joint.placement.rotation;  // joint frame at q = 0
      X_WB.translation = X_WP.act(joint.placement.translation);
      const Vector3 axis_W = R_WJ * joint.axis;
      const double qi = q[i - 1];
      if (joint.type == JointType::kRevolute) {
        X_WB.rotation.noalias() = R_WJ * detail::axis_rotation(joint.axis, qi);
        // Revolute about axis z through O_i: velocity of the body point at the world origin
        // is O_i x z q_dot.
        data.S[i] << X_WB.translation.cross(axis_W), axis_W;
      } else {
        X_WB.rotation = R_WJ;
        X_WB.translation += axis_W * qi;
        data.S[i] << axis_W, Vector3::Zero();
      }
    }
    // Mass properties about the world origin: h = m c_W, I_O = R I_c R^T + m (|c|^2 1 - c c^T).
    const Inertia& inertia = model.bodies[i].inertia;
    const Pose& X = data.X_WB[i];
    const Vector3 c_W = X.act(inertia.com);
    const double m = inertia.mass;
    data.mass[i] = m;
    data.first_moment_W[i] = m * c_W;
    Matrix3& I_O = data.inertia_O_W[i];
    I_O.noalias() = X.rotation * inertia.inertia_com * X.rotation.transpose();
    I_O.diagonal().array() += m * c_W.squaredNorm();
    I_O.noalias() -= m * c_W * c_W.transpose();
  }
}

Pose frame_pose(const Model& model, const Data& data, int frame) {
  const Frame& fr = model.frames[static_cast<std::size_t>(frame)];
  return data.X_WB[fr.body] * fr.placement;
}

void point_jacobian(const Model& model, const Data& data, int body, const Vector3& p_W,
                    Eigen::Ref<Matrix6X> J) {
  J.setZero();
  // Point velocity = v_O + w x p: column j = [S_lin + S_ang x p; S_ang] for the ancestors j.
  for (int j = body; j > 0; j = model.parents[j]) {
    const Vector6& s = data.S[j];
    J.col(j - 1).head<3>() = s.head<3>() + s.tail<3>().cross(p_W);
    J.col(j - 1).tail<3>() = s.tail<3>();
  }
}

const Matrix6X& body_jacobian(const Model& model, Data& data, int body) {
  point_jacobian(model, data, body, data.X_WB[body].translation, data.J);
  return data.J;
}

}  // namespace extwrench
