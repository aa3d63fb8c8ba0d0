// The mutable workspace of the dynamics algorithms: every buffer sized once from a Model, so
// that no algorithm allocates afterwards. One Data per thread; the Model is shared (const).
#pragma once

#include <Eigen/Cholesky>
#include <vector>

#include "extwrench/model/model.hpp"

namespace extwrench {

/// Body quantities are indexed like Model::bodies (size n + 1, index 0 = link 0).
/// Spatial vectors are [linear; angular], expressed in the world (root) frame and taken about
/// the world origin (a velocity's linear part is that of the body point at the world origin).
struct Data {
  explicit Data(const Model& model);

  /// True if this Data was sized for `model` and its cached terms (rotation_const, rotation_cos,
  /// rotation_sin and their transposes, axis_P, S_B, slide_P, aligned) are those of model's joints
  /// and bodies: a Data built for one Model is not valid for another of the same size whose joint
  /// axes, placements or inertias differ. After editing a Model, build a new Data: the dynamics
  /// functions check the sizes, not this (a full comparison per call).
  [[nodiscard]] bool matches(const Model& model) const;

  // --- derived from the model once, for the hot path ---
  /// Joint i's rotation from the parent body frame as E_i(q) = rotation_const + cos q ·
  /// rotation_cos + sin q · rotation_sin (Rodrigues premultiplied by the placement rotation P_i:
  /// P_i (a aᵀ + cos q (1 − a aᵀ) + sin q [a]×), a the unit axis; prismatic: P_i, 0, 0), so the
  /// pose pass is the same two fixed-size 3x3 products for every joint, with no branch on its
  /// type or axis and nothing indexed at run time.
  std::vector<Matrix3> rotation_const, rotation_cos, rotation_sin;
  std::vector<Vector3> axis_P;  ///< P_i a: joint i's axis in the parent body frame
  /// The transposes of rotation_const, rotation_cos, rotation_sin: E_i(q)^T from them is a
  /// combination of columns (gravity_torques' forward pass, g_i = E_i^T g_p).
  std::vector<Matrix3> rotation_const_T, rotation_cos_T, rotation_sin_T;
  /// Joint i's motion subspace in body i's own frame, about its origin (a point of the axis):
  /// revolute [0; a], prismatic [a; 0]. Constant: gravity_torques works in body frames with it.
  std::vector<Vector6> S_B;
  /// The parent-frame translation of joint i per unit of q: P_i a for a prismatic joint, zero for
  /// a revolute one, so body i's origin in its parent is placement + slide_P q for every joint.
  std::vector<Vector3> slide_P;

  /// rnea's frames: body i's own frame turned so that its joint axis is +z, J_i = B_i A_i with a
  /// constant rotation A_i (A_i e_z = the axis; A_i = 1 when the axis is +z). In them the joint's
  /// rotation is AlignedBody::rotation · Rz(q), formed from two columns, and the motion subspace is
  /// e_z: the recursion's joint terms are a few scalars (docs/algorithms.md, "Inverse dynamics").
  /// Derived from the Model once, mass properties included: build a new Data after changing a
  /// body's inertia (the other algorithms read the Model's).
  struct AlignedBody {
    Matrix3 rotation = Matrix3::Identity();  ///< A_pᵀ P_i A_i: E'_i(q) = rotation · Rz(q)
    /// Its transpose: E'_i(q)ᵀ x as a combination of columns (no horizontal sums).
    Matrix3 rotation_T = Matrix3::Identity();
    Vector3 translation = Vector3::Zero();  ///< A_pᵀ t_i: the joint's origin in J_p at q = 0
    Vector3 slide = Vector3::Zero();  ///< A_pᵀ P_i a per unit of q (prismatic), zero (revolute)
    double revolute = 1.0;            ///< 1 revolute, 0 prismatic
    Matrix3 alignment = Matrix3::Identity();  ///< A_i
    double mass = 0.0;                        ///< m_i
    Vector3 first_moment = Vector3::Zero();   ///< m_i c_i in J_i
    Matrix3 inertia_O = Matrix3::Zero();      ///< rotational inertia about J_i's origin, in J_i
    bool operator==(const AlignedBody&) const = default;
  };
  std::vector<AlignedBody> aligned;
  /// Scratch of rnea, in each body's J_i: its angular velocity w, [a; w_dot] (a the classical
  /// acceleration of J_i's origin) and the wrench [F; N] its joint transmits (about that origin).
  std::vector<Vector3> w_J;
  std::vector<Vector6> a_J, f_J;

  // --- forward kinematics (forward_kinematics) ---
  std::vector<Pose> X_WB;  ///< pose of each body frame in the world
  std::vector<Vector6> S;  ///< joint motion subspace of body i's joint (world, at origin)
  // World-frame mass properties, about the world origin: m, h = m c_W, I_O.
  std::vector<double> mass;             ///< m_i (copy, so the hot path reads one array)
  std::vector<Vector3> first_moment_W;  ///< h_i = m_i c_i (world)
  std::vector<Matrix3> inertia_O_W;     ///< rotational inertia about the world origin

  // --- velocities / accelerations / forces (rnea_no_kinematics & co.; rnea uses w_J, a_J, f_J) ---
  std::vector<Vector6> v;       ///< spatial velocity of body i
  std::vector<Vector6> a;       ///< spatial acceleration of body i (gravity trick included)
  std::vector<Vector6> f;       ///< spatial force transmitted by joint i to body i (f_i)
  std::vector<Vector6> h;       ///< spatial momentum of body i (I_i v_i)
  std::vector<Vector6> bias_f;  ///< scratch of momentum_and_bias_terms: bias wrench of each subtree

  // --- results ---
  VectorX tau;  ///< (n) joint torques of the last rnea / bias / gravity
  Vector6 root_wrench_W =
      Vector6::Zero();  ///< f_0: wrench the ground applies to link 0, world, about the world origin
  MatrixX M;            ///< (n x n) mass matrix B(q), both triangles filled
  MatrixX C;            ///< (n x n) Coriolis matrix with B_dot = C + C^T
  VectorX momentum;     ///< (n) generalized momentum B(q) q_dot
  VectorX coriolis_transpose_dq;  ///< (n) C^T(q, q_dot) q_dot = dT/dq
  VectorX gravity_torque;         ///< (n) g(q)
  VectorX ddq;                    ///< (n) result of forward_dynamics
  Matrix6X J;                     ///< (6 x n) last Jacobian computed

  // --- scratch ---
  // Composite mass properties of each subtree about the world origin: (m, h, I_O) add up
  // directly since every body's are expressed at the same point in the same axes.
  std::vector<double> composite_mass;
  std::vector<Vector3> composite_first_moment;
  std::vector<Matrix3> composite_inertia_O;
  // gravity_torques works in body frames instead, without any world pose (docs/algorithms.md):
  std::vector<Vector3>
      composite_first_moment_B;           ///< subtree's m c about body i's origin, body i axes
  std::vector<Vector3> gravity_B;         ///< the gravity vector g_i in body i's axes
  std::vector<double> gravity_lin_B;      ///< S_B,lin . g_i
  std::vector<Vector3> gravity_moment_B;  ///< g_i x S_B,ang
  std::vector<Matrix6> Ic;       ///< composite spatial inertia of each subtree (world, origin)
  std::vector<Matrix6> Bc;       ///< composite v x* I of each subtree (for C)
  std::vector<Vector6> Sdot;     ///< time derivative of S
  VectorX tmp_n;                 ///< (n) scratch
  VectorX sin_q, cos_q;          ///< (n) sin and cos of each joint coordinate (pose passes)
  Eigen::LLT<MatrixX> mass_llt;  ///< factorization of M, sized once
};

}  // namespace extwrench
