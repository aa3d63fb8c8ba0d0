#include "extwrench/dynamics/kinematics.hpp"

#include "spatial.hpp"

namespace extwrench {

void forward_kinematics(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  detail::poses_and_subspaces(model, data, q);
  world_mass_properties(model, data);
}

void world_mass_properties(const Model& model, Data& data) {
  const int nb = model.num_bodies();
  for (int i = 0; i < nb; ++i) {
    // Mass properties about the world origin: h = m c_W, I_O = R I_c R^T + m (|c|^2 1 - c c^T).
    const Inertia& inertia = model.bodies[i].inertia;
    const Pose& X = data.X_WB[i];
    const Vector3 c_W = X.act(inertia.com);
    const double m = inertia.mass;
    data.mass[i] = m;
    data.first_moment_W[i] = m * c_W;
    // Symmetric: A = R I_c once, then only the lower triangle of A R^T + m (|c|^2 1 - c c^T).
    Matrix3 A;
    A.noalias() = X.rotation * inertia.inertia_com;
    const Vector3 h = m * c_W;
    const double mc2 = h.dot(c_W);
    Matrix3& I_O = data.inertia_O_W[i];
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col <= r; ++col) {
        const double e = A.row(r).dot(X.rotation.row(col)) - h[r] * c_W[col];
        I_O(r, col) = e;
        I_O(col, r) = e;
      }
      I_O(r, r) += mc2;
    }
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
