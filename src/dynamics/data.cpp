#include "extwrench/dynamics/data.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace extwrench {

namespace {

/// The cached rotation terms of one joint (see Data::rotation_const), written once here so that
/// the constructor and Data::matches derive them the same way.
struct JointRotation {
  Matrix3 rotation_const = Matrix3::Identity();
  Matrix3 rotation_cos = Matrix3::Zero();
  Matrix3 rotation_sin = Matrix3::Zero();
  Vector3 axis_P = Vector3::Zero();
  Vector6 S_B = Vector6::Zero();
  Vector3 slide_P = Vector3::Zero();
};

JointRotation joint_rotation(const Joint& joint) {
  JointRotation out;
  const Matrix3& P = joint.placement.rotation;
  const Vector3& a = joint.axis;
  out.axis_P = P * a;
  if (joint.type == JointType::kRevolute) {
    const Matrix3 aaT = a * a.transpose();
    out.rotation_const = P * aaT;
    out.rotation_cos = P * (Matrix3::Identity() - aaT);
    out.rotation_sin = P * skew(a);
    out.S_B.tail<3>() = a;
  } else {
    out.rotation_const = P;
    out.S_B.head<3>() = a;
    out.slide_P = out.axis_P;
  }
  return out;
}

/// A_i: a rotation taking e_z to the unit axis (the identity for +z, so that a model whose axes
/// are all +z keeps its body frames).
Matrix3 axis_alignment(const Joint& joint) {
  if (joint.axis == Vector3::UnitZ()) return Matrix3::Identity();
  return Eigen::Quaterniond::FromTwoVectors(Vector3::UnitZ(), joint.axis).toRotationMatrix();
}

/// Data::aligned of every body, from the model's joints and inertias.
std::vector<Data::AlignedBody> aligned_bodies(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.num_bodies());
  std::vector<Data::AlignedBody> out(nb);
  for (std::size_t i = 0; i < nb; ++i) {
    Data::AlignedBody& b = out[i];
    if (i > 0 && i < model.joints.size()) {
      const Joint& joint = model.joints[i];
      const auto p = static_cast<std::size_t>(model.parents[i]);
      b.alignment = axis_alignment(joint);
      const Matrix3 parent_T = out[p].alignment.transpose();
      b.rotation = parent_T * joint.placement.rotation * b.alignment;
      b.rotation_T = b.rotation.transpose();
      b.translation = parent_T * joint.placement.translation;
      b.revolute = joint.type == JointType::kRevolute ? 1.0 : 0.0;
      if (joint.type != JointType::kRevolute)
        b.slide = parent_T * (joint.placement.rotation * joint.axis);
    }
    const Inertia& inertia = model.bodies[i].inertia;
    const Vector3& c = inertia.com;
    const Matrix3 inertia_O =
        inertia.inertia_com +
        inertia.mass * (c.squaredNorm() * Matrix3::Identity() - c * c.transpose());
    b.mass = inertia.mass;
    b.first_moment = inertia.mass * (b.alignment.transpose() * c);
    b.inertia_O = b.alignment.transpose() * inertia_O * b.alignment;
  }
  return out;
}

template <typename T>
bool sized(const std::vector<T>& v, std::size_t size) {
  return v.size() == size;
}

}  // namespace

Data::Data(const Model& model) {
  const auto nb = static_cast<std::size_t>(model.num_bodies());
  const int n = model.nq();
  rotation_const.assign(nb, Matrix3::Identity());
  rotation_cos.assign(nb, Matrix3::Zero());
  rotation_sin.assign(nb, Matrix3::Zero());
  axis_P.assign(nb, Vector3::Zero());
  rotation_const_T.assign(nb, Matrix3::Identity());
  rotation_cos_T.assign(nb, Matrix3::Zero());
  rotation_sin_T.assign(nb, Matrix3::Zero());
  S_B.assign(nb, Vector6::Zero());
  slide_P.assign(nb, Vector3::Zero());
  for (std::size_t i = 1; i < nb && i < model.joints.size(); ++i) {
    const JointRotation r = joint_rotation(model.joints[i]);
    rotation_const[i] = r.rotation_const;
    rotation_cos[i] = r.rotation_cos;
    rotation_sin[i] = r.rotation_sin;
    axis_P[i] = r.axis_P;
    rotation_const_T[i] = r.rotation_const.transpose();
    rotation_cos_T[i] = r.rotation_cos.transpose();
    rotation_sin_T[i] = r.rotation_sin.transpose();
    S_B[i] = r.S_B;
    slide_P[i] = r.slide_P;
  }
  aligned = aligned_bodies(model);
  w_J.assign(nb, Vector3::Zero());
  a_J.assign(nb, Vector6::Zero());
  f_J.assign(nb, Vector6::Zero());
  X_WB.assign(nb, Pose{});
  S.assign(nb, Vector6::Zero());
  mass.assign(nb, 0.0);
  first_moment_W.assign(nb, Vector3::Zero());
  inertia_O_W.assign(nb, Matrix3::Zero());
  v.assign(nb, Vector6::Zero());
  a.assign(nb, Vector6::Zero());
  f.assign(nb, Vector6::Zero());
  h.assign(nb, Vector6::Zero());
  bias_f.assign(nb, Vector6::Zero());
  composite_mass.assign(nb, 0.0);
  composite_first_moment.assign(nb, Vector3::Zero());
  composite_inertia_O.assign(nb, Matrix3::Zero());
  composite_first_moment_B.assign(nb, Vector3::Zero());
  gravity_B.assign(nb, Vector3::Zero());
  gravity_lin_B.assign(nb, 0.0);
  gravity_moment_B.assign(nb, Vector3::Zero());
  Ic.assign(nb, Matrix6::Zero());
  Bc.assign(nb, Matrix6::Zero());
  Sdot.assign(nb, Vector6::Zero());
  tau = VectorX::Zero(n);
  M = MatrixX::Zero(n, n);
  C = MatrixX::Zero(n, n);
  momentum = VectorX::Zero(n);
  coriolis_transpose_dq = VectorX::Zero(n);
  gravity_torque = VectorX::Zero(n);
  ddq = VectorX::Zero(n);
  J = Matrix6X::Zero(6, n);
  tmp_n = VectorX::Zero(n);
  sin_q = VectorX::Zero(n);
  cos_q = VectorX::Zero(n);
  // Sized by a factorization rather than by copying LLT(n), whose ComputationInfo is left
  // uninitialized by Eigen (UBSan: invalid enum load in the copy).
  mass_llt.compute(MatrixX::Identity(n, n));
}

bool Data::matches(const Model& model) const {
  const auto nb = static_cast<std::size_t>(model.num_bodies());
  const Eigen::Index n = model.nq();
  const bool bodies_sized =
      sized(rotation_const, nb) && sized(rotation_cos, nb) && sized(rotation_sin, nb) &&
      sized(axis_P, nb) && sized(rotation_const_T, nb) && sized(rotation_cos_T, nb) &&
      sized(rotation_sin_T, nb) && sized(S_B, nb) && sized(slide_P, nb) && sized(X_WB, nb) &&
      sized(S, nb) && sized(mass, nb) && sized(first_moment_W, nb) && sized(inertia_O_W, nb) &&
      sized(v, nb) && sized(a, nb) && sized(f, nb) && sized(h, nb) && sized(bias_f, nb) &&
      sized(composite_mass, nb) && sized(composite_first_moment, nb) &&
      sized(composite_inertia_O, nb) && sized(composite_first_moment_B, nb) &&
      sized(gravity_B, nb) && sized(gravity_lin_B, nb) && sized(gravity_moment_B, nb) &&
      sized(Ic, nb) && sized(Bc, nb) && sized(Sdot, nb) && sized(w_J, nb) && sized(a_J, nb) &&
      sized(f_J, nb);
  const bool joints_sized = tau.size() == n && M.rows() == n && M.cols() == n && C.rows() == n &&
                            C.cols() == n && momentum.size() == n &&
                            coriolis_transpose_dq.size() == n && gravity_torque.size() == n &&
                            ddq.size() == n && J.cols() == n && tmp_n.size() == n &&
                            sin_q.size() == n && cos_q.size() == n;
  if (!bodies_sized || !joints_sized) return false;
  for (std::size_t i = 1; i < nb && i < model.joints.size(); ++i) {
    const JointRotation r = joint_rotation(model.joints[i]);
    if (r.rotation_const != rotation_const[i] || r.rotation_cos != rotation_cos[i] ||
        r.rotation_sin != rotation_sin[i] || r.axis_P != axis_P[i] || r.S_B != S_B[i] ||
        r.slide_P != slide_P[i] || r.rotation_const.transpose() != rotation_const_T[i] ||
        r.rotation_cos.transpose() != rotation_cos_T[i] ||
        r.rotation_sin.transpose() != rotation_sin_T[i]) {
      return false;
    }
  }
  return aligned == aligned_bodies(model);
}

}  // namespace extwrench
