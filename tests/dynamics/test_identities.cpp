// A property suite spanning several sources, so it keeps its own name (docs/layout.md, Tests).
// Physical and algebraic identities of the dynamics on random serial chains and trees:
// every algorithm checked against another path (finite differences, RNEA columns, Newton's law).
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/momentum.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/model/sample_models.hpp"
#include "momentum_oracle.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

// Central differences with step 1e-6 have truncation error ~1e-12 * third derivative and
// round-off ~1e-16 / 1e-6: 1e-7 relative is a comfortable bound for these smooth functions.
constexpr double kFiniteDifferenceTol = 1e-7;
constexpr double kFdStep = 1e-6;
// Algebraic identities that only reorder floating-point operations.
constexpr double kAlgebraicTol = 1e-10;
constexpr int kStates = 200;

struct Case {
  const char* name;
  RandomChainOptions options;
};

class DynamicsIdentities : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override { model_ = random_chain(GetParam().options); }
  Model model_;
};

double scale(const MatrixX& m) { return std::max(1.0, m.cwiseAbs().maxCoeff()); }

TEST_P(DynamicsIdentities, MassMatrixDerivativeEqualsCPlusCTranspose) {
  Data data(model_);
  SeededRng rng(11);
  const int n = model_.nq();
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    const MatrixX m_plus = crba(model_, data, q + kFdStep * dq);
    const MatrixX m_minus = crba(model_, data, q - kFdStep * dq);
    const MatrixX b_dot = (m_plus - m_minus) / (2 * kFdStep);
    const MatrixX c = coriolis_matrix(model_, data, q, dq);
    EXPECT_LE((b_dot - c - c.transpose()).cwiseAbs().maxCoeff(),
              kFiniteDifferenceTol * scale(b_dot));
  }
}

TEST_P(DynamicsIdentities, CoriolisTimesVelocityPlusGravityEqualsBiasTorques) {
  Data data(model_);
  SeededRng rng(12);
  const int n = model_.nq();
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    const VectorX c_dq = coriolis_matrix(model_, data, q, dq) * dq;
    const VectorX g = gravity_torques(model_, data, q);
    const VectorX bias = bias_torques(model_, data, q, dq);
    EXPECT_LE((c_dq + g - bias).cwiseAbs().maxCoeff(), kAlgebraicTol * scale(bias));
  }
}

TEST_P(DynamicsIdentities, CoriolisTransposeTimesVelocityEqualsKineticEnergyGradient) {
  Data data(model_);
  SeededRng rng(13);
  const int n = model_.nq();
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    VectorX dT(n);
    for (int i = 0; i < n; ++i) {
      VectorX qp = q, qm = q;
      qp[i] += kFdStep;
      qm[i] -= kFdStep;
      const double tp = 0.5 * dq.dot(crba(model_, data, qp) * dq);
      const double tm = 0.5 * dq.dot(crba(model_, data, qm) * dq);
      dT[i] = (tp - tm) / (2 * kFdStep);
    }
    momentum_terms(model_, data, q, dq);
    const VectorX ctdq = data.coriolis_transpose_dq;
    EXPECT_LE((ctdq - dT).cwiseAbs().maxCoeff(), kFiniteDifferenceTol * scale(dT));
    const VectorX c_explicit = coriolis_matrix(model_, data, q, dq).transpose() * dq;
    EXPECT_LE((ctdq - c_explicit).cwiseAbs().maxCoeff(), kAlgebraicTol * scale(c_explicit));
  }
}

TEST_P(DynamicsIdentities, MomentumTermsMatchMassMatrixAndGravity) {
  Data data(model_);
  SeededRng rng(14);
  const int n = model_.nq();
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    const VectorX b_dq = crba(model_, data, q) * dq;
    const VectorX g = gravity_torques(model_, data, q);
    momentum_terms(model_, data, q, dq);
    EXPECT_LE((data.momentum - b_dq).cwiseAbs().maxCoeff(), kAlgebraicTol * scale(b_dq));
    EXPECT_LE((data.gravity_torque - g).cwiseAbs().maxCoeff(), kAlgebraicTol * scale(g));
  }
}

TEST_P(DynamicsIdentities, MomentumPassMatchesTheSixVectorOracle) {
  Data data(model_);
  Data oracle(model_);
  SeededRng rng(16);
  const int n = model_.nq();
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    momentum_terms(model_, data, q, dq);
    forward_kinematics(model_, oracle, q);
    test::momentum_terms_oracle(model_, oracle, dq);
    EXPECT_LE((data.momentum - oracle.momentum).cwiseAbs().maxCoeff(),
              kAlgebraicTol * scale(oracle.momentum));
    EXPECT_LE((data.coriolis_transpose_dq - oracle.coriolis_transpose_dq).cwiseAbs().maxCoeff(),
              kAlgebraicTol * scale(oracle.coriolis_transpose_dq));
    EXPECT_LE((data.gravity_torque - oracle.gravity_torque).cwiseAbs().maxCoeff(),
              kAlgebraicTol * scale(oracle.gravity_torque));
  }
}

// The gravity pass (body frames, subtree first moments) against the two earlier paths to g(q):
// rnea at rest, and forward kinematics + the whole bias pass at q_dot = q_ddot = 0 (what
// gravity_torques ran before issue 15). Reordered floating point only: 1e-12 relative.
constexpr double kGravityTol = 1e-12;

double gravity_error_against_bias_pass(const Model& model, Data& data, Data& other,
                                       const VectorX& q) {
  const VectorX g = gravity_torques(model, data, q);
  const VectorX zero = VectorX::Zero(model.nq());
  const VectorX at_rest = rnea(model, other, q, zero, zero);
  forward_kinematics(model, other, q);
  const VectorX bias_pass = rnea_no_kinematics(model, other, zero, zero, {}, true);
  return std::max(test::relative_error(g, at_rest), test::relative_error(g, bias_pass));
}

TEST_P(DynamicsIdentities, GravityPassEqualsRneaAtRestAndTheBiasPass) {
  Data data(model_);
  Data other(model_);
  SeededRng rng(22);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(model_.nq(), -3, 3);
    EXPECT_LE(gravity_error_against_bias_pass(model_, data, other, q), kGravityTol) << k;
  }
}

// Angles that exercise the passes' own sin/cos (no libm call below 2^20 rad): every quadrant,
// its seams (multiples of pi/4), far out, and past 2^20 rad where it falls back to libm.
VectorX large_angle_state(const Model& model, SeededRng& rng, int k) {
  const int n = model.nq();
  VectorX q = rng.uniform_vector(n, -1e4, 1e4);
  if (k % 4 == 1) {
    for (int i = 0; i < n; ++i) q[i] = (k / 4 % 17 - 8 + i) * (std::numbers::pi / 4);
  } else if (k % 4 == 2) {
    q = rng.uniform_vector(n, -3e6, 3e6);
  }
  // Angles only: a prismatic joint stays within a metre (kilometres of lever arm would test
  // cancellation in the torques, not the sines).
  for (int i = 0; i < n; ++i) {
    if (model.joints[i + 1].type == JointType::kPrismatic) q[i] = std::remainder(q[i], 1.0);
  }
  return q;
}

TEST_P(DynamicsIdentities, GravityPassHoldsAtLargeAnglesAndQuadrantSeams) {
  Data data(model_);
  Data other(model_);
  SeededRng rng(25);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = large_angle_state(model_, rng, k);
    EXPECT_LE(gravity_error_against_bias_pass(model_, data, other, q), kGravityTol) << k;
  }
}

// rnea (joint-aligned body frames, its own sin/cos) and crba (fused, its own sin/cos) against
// the world-frame two-step paths after forward_kinematics (glibc's sincos).
TEST_P(DynamicsIdentities, RneaAndCrbaHoldAtLargeAnglesAndQuadrantSeams) {
  Data data(model_);
  Data other(model_);
  SeededRng rng(27);
  const int n = model_.nq();
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = large_angle_state(model_, rng, k);
    const VectorX dq = rng.uniform_vector(n, -2, 2), ddq = rng.uniform_vector(n, -5, 5);
    const VectorX tau = rnea(model_, data, q, dq, ddq);
    const Vector6 root = data.root_wrench_W;
    const MatrixX m = crba(model_, data, q);
    forward_kinematics(model_, other, q);
    const VectorX tau_ref = rnea_no_kinematics(model_, other, dq, ddq);
    EXPECT_LE(test::relative_error(tau, tau_ref), 1e-12) << k;
    EXPECT_LE(test::relative_error(root, other.root_wrench_W), 1e-12) << k;
    EXPECT_LE(test::relative_error(m, crba_no_kinematics(model_, other)), 1e-12) << k;
  }
}

TEST_P(DynamicsIdentities, GravityPassIgnoresArmatureAndWhatDataHeld) {
  Model with_armature = model_;
  SeededRng rng(23);
  for (Joint& j : with_armature.joints) j.armature = rng.uniform(0.01, 0.5);
  Data data(model_);
  Data used(with_armature);
  for (int k = 0; k < 20; ++k) {
    const VectorX q = rng.uniform_vector(model_.nq(), -3, 3);
    const VectorX g = gravity_torques(model_, data, q);
    // `used` last held another state's poses, momenta and bias terms.
    const VectorX q_other = rng.uniform_vector(model_.nq(), -3, 3);
    momentum_and_bias_terms(with_armature, used, q_other, rng.uniform_vector(model_.nq(), -2, 2));
    EXPECT_EQ(gravity_torques(with_armature, used, q), g) << k;
  }
}

TEST(GravityPass, PaperArmEqualsRneaAtRestAndTheBiasPass) {
  const Model model = paper_arm();
  Data data(model);
  Data other(model);
  SeededRng rng(24);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(model.nq(), -3.1, 3.1);
    EXPECT_LE(gravity_error_against_bias_pass(model, data, other, q), kGravityTol) << k;
  }
}

TEST_P(DynamicsIdentities, ForwardPosesAreTheForwardKinematicsPosesBitForBit) {
  Data data(model_);
  Data full(model_);
  SeededRng rng(26);
  for (int k = 0; k < 20; ++k) {
    const VectorX q = rng.uniform_vector(model_.nq(), -3, 3);
    forward_poses(model_, data, q);
    forward_kinematics(model_, full, q);
    for (int i = 0; i < model_.num_bodies(); ++i) {
      EXPECT_EQ(data.X_WB[i].rotation, full.X_WB[i].rotation) << k << " body " << i;
      EXPECT_EQ(data.X_WB[i].translation, full.X_WB[i].translation) << k << " body " << i;
      EXPECT_EQ(data.S[i], full.S[i]) << k << " body " << i;
    }
  }
}

// crba runs its own fused pass (its own sin/cos, composites carried along chains); the
// two-step path forward_kinematics + crba_no_kinematics (glibc's sincos, world mass properties
// stored first) is what the estimator uses. Same algebra, different rounding: within 1e-12.
TEST_P(DynamicsIdentities, CrbaMatchesForwardKinematicsThenCrbaNoKinematics) {
  Data fused(model_);
  Data two_step(model_);
  SeededRng rng(19);
  const int n = model_.nq();
  double worst = 0.0;
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3);
    const MatrixX m = crba(model_, fused, q);
    forward_kinematics(model_, two_step, q);
    const MatrixX& m_ref = crba_no_kinematics(model_, two_step);
    const double e = test::relative_error(m, m_ref);
    worst = std::max(worst, e);
    EXPECT_LE(e, 1e-12) << "state " << k;
    EXPECT_EQ(m, m.transpose()) << "state " << k;
    // The poses and motion subspaces crba leaves in data, as forward_poses computes them.
    for (int i = 0; i < model_.num_bodies(); ++i) {
      EXPECT_LE(test::relative_error(fused.X_WB[i].rotation, two_step.X_WB[i].rotation), 1e-12);
      EXPECT_LE(test::relative_error(fused.X_WB[i].translation, two_step.X_WB[i].translation),
                1e-12);
      EXPECT_LE(test::relative_error(fused.S[i], two_step.S[i]), 1e-12);
    }
  }
  std::printf("[ worst    ] %s crba vs forward_kinematics + crba_no_kinematics %.3e\n",
              GetParam().name, worst);
}

TEST_P(DynamicsIdentities, MassMatrixEqualsRneaColumns) {
  Data data(model_);
  SeededRng rng(15);
  const int n = model_.nq();
  const VectorX zero = VectorX::Zero(n);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3);
    const MatrixX m = crba(model_, data, q);
    const VectorX g = rnea(model_, data, q, zero, zero);
    for (int i = 0; i < n; ++i) {
      const VectorX column = rnea(model_, data, q, zero, VectorX::Unit(n, i)) - g;
      EXPECT_LE((m.col(i) - column).cwiseAbs().maxCoeff(), kAlgebraicTol * scale(m));
    }
    EXPECT_GT(Eigen::LLT<MatrixX>(m).info() == Eigen::Success, 0);
  }
}

TEST_P(DynamicsIdentities, ForwardDynamicsInvertsRnea) {
  Data data(model_);
  SeededRng rng(16);
  const int n = model_.nq();
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    const VectorX ddq = rng.uniform_vector(n, -5, 5);
    const VectorX tau = rnea(model_, data, q, dq, ddq);
    ASSERT_TRUE(forward_dynamics(model_, data, q, dq, tau));
    EXPECT_LE((data.ddq - ddq).cwiseAbs().maxCoeff(), 1e-8 * scale(ddq));
  }
}

TEST_P(DynamicsIdentities, ExternalWrenchEntersAsJacobianTranspose) {
  Data data(model_);
  SeededRng rng(17);
  const int n = model_.nq();
  Matrix6X J(6, n);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    const VectorX ddq = rng.uniform_vector(n, -5, 5);
    const VectorX tau_free = rnea(model_, data, q, dq, ddq);
    forward_poses(model_, data, q);
    ExternalWrench w;
    w.body = 1 + k % n;
    w.force_W = rng.uniform_vector3(-20, 20);
    w.moment_W = rng.uniform_vector3(-5, 5);
    w.point_W = data.X_WB[w.body].act(rng.uniform_vector3(-0.2, 0.2));
    const VectorX tau_ext = rnea(model_, data, q, dq, ddq, std::span(&w, 1));
    point_jacobian(model_, data, w.body, w.point_W, J);
    Vector6 wrench;
    wrench << w.force_W, w.moment_W;
    const VectorX expected = tau_free - J.transpose() * wrench;
    EXPECT_LE((tau_ext - expected).cwiseAbs().maxCoeff(), kAlgebraicTol * scale(expected));
  }
}

TEST_P(DynamicsIdentities, PointJacobianMatchesFiniteDifferencesOfKinematics) {
  Data data(model_);
  SeededRng rng(18);
  const int n = model_.nq();
  Matrix6X J(6, n);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    const int body = 1 + k % n;
    const Vector3 p_B = rng.uniform_vector3(-0.2, 0.2);
    forward_kinematics(model_, data, q + kFdStep * dq);
    const Pose plus = data.X_WB[body];
    forward_kinematics(model_, data, q - kFdStep * dq);
    const Pose minus = data.X_WB[body];
    forward_kinematics(model_, data, q);
    point_jacobian(model_, data, body, data.X_WB[body].act(p_B), J);
    const Vector6 twist = J * dq;
    const Vector3 v_fd = (plus.act(p_B) - minus.act(p_B)) / (2 * kFdStep);
    // R_dot R^T = S(w)
    const Matrix3 w_hat =
        (plus.rotation - minus.rotation) / (2 * kFdStep) * data.X_WB[body].rotation.transpose();
    const Vector3 w_fd(w_hat(2, 1), w_hat(0, 2), w_hat(1, 0));
    EXPECT_LE((twist.head<3>() - v_fd).norm(), kFiniteDifferenceTol * (1 + v_fd.norm()));
    EXPECT_LE((twist.tail<3>() - w_fd).norm(), kFiniteDifferenceTol * (1 + w_fd.norm()));
  }
}

// Newton-Euler for the whole robot, an independent path to the base reading:
// f_m = sum F_ext + M g - P_dot and n_m = sum (M_ext + (p - O_s) x F_ext) + (c - O_s) x M g - L_dot
// (L about the fixed point O_s), with P and L from the bodies' velocities and P_dot, L_dot by
// central differences along the motion.
struct Momenta {
  Vector3 linear, angular_about_sensor;
};

Momenta robot_momenta(const Model& model, Data& data, const VectorX& q, const VectorX& dq,
                      const Vector3& p_WS) {
  forward_kinematics(model, data, q);
  Momenta out{Vector3::Zero(), Vector3::Zero()};
  Matrix6X J(6, model.nq());
  for (int i = 1; i < model.num_bodies(); ++i) {
    const Inertia& in = model.bodies[i].inertia;
    const Vector3 c_W = data.X_WB[i].act(in.com);
    point_jacobian(model, data, i, c_W, J);
    const Vector6 twist = J * dq;
    const Vector3 p = in.mass * twist.head<3>();
    const Matrix3 R = data.X_WB[i].rotation;
    out.linear += p;
    out.angular_about_sensor +=
        (c_W - p_WS).cross(p) + R * in.inertia_com * R.transpose() * twist.tail<3>();
  }
  return out;
}

TEST_P(DynamicsIdentities, BaseReadingObeysNewtonEulerForTheWholeRobot) {
  Data data(model_);
  SeededRng rng(19);
  const int n = model_.nq();
  const double h = 1e-5;
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3), dq = rng.uniform_vector(n, -2, 2);
    const VectorX ddq = rng.uniform_vector(n, -5, 5);
    const Pose X_WS =
        Pose::from_xyz_rpy(rng.uniform_vector3(-0.5, 0.5), rng.uniform_vector3(-3, 3));
    ExternalWrench w;
    w.body = k % (n + 1);
    w.force_W = rng.uniform_vector3(-20, 20);
    w.moment_W = rng.uniform_vector3(-5, 5);
    // Along q(t) with the given dq, ddq: second-order Taylor, so the central difference of the
    // momenta at t = 0 is exact to O(h^2).
    const Momenta plus =
        robot_momenta(model_, data, q + h * dq + 0.5 * h * h * ddq, dq + h * ddq, X_WS.translation);
    const Momenta minus =
        robot_momenta(model_, data, q - h * dq + 0.5 * h * h * ddq, dq - h * ddq, X_WS.translation);
    const Vector3 p_dot = (plus.linear - minus.linear) / (2 * h);
    const Vector3 l_dot = (plus.angular_about_sensor - minus.angular_about_sensor) / (2 * h);

    forward_kinematics(model_, data, q);
    w.point_W = data.X_WB[w.body].act(rng.uniform_vector3(-0.2, 0.2));
    double total_mass = 0;
    Vector3 first_moment = Vector3::Zero();
    for (int i = 0; i <= n; ++i) {
      total_mass += data.mass[i];
      first_moment += data.first_moment_W[i];
    }
    const Vector3 com = first_moment / total_mass;
    rnea(model_, data, q, dq, ddq, std::span(&w, 1));
    const Vector6 reading_W = sensor_reading_world(data, X_WS.translation);
    const Vector6 reading_S = sensor_reading(data, X_WS);

    const Vector3 weight = total_mass * model_.gravity;
    const Vector3 f_expected = w.force_W + weight - p_dot;
    const Vector3 n_expected = w.moment_W + (w.point_W - X_WS.translation).cross(w.force_W) +
                               (com - X_WS.translation).cross(weight) - l_dot;
    EXPECT_LE((reading_W.head<3>() - f_expected).norm(), 1e-6 * (1 + f_expected.norm()));
    EXPECT_LE((reading_W.tail<3>() - n_expected).norm(), 1e-6 * (1 + n_expected.norm()));
    EXPECT_LE((X_WS.rotation * reading_S.head<3>() - reading_W.head<3>()).norm(),
              1e-12 * (1 + f_expected.norm()));
    EXPECT_LE((X_WS.rotation * reading_S.tail<3>() - reading_W.tail<3>()).norm(),
              1e-12 * (1 + n_expected.norm()));
  }
}

TEST_P(DynamicsIdentities, StaticRobotDischargesItsWeightAndItsMoment) {
  Data data(model_);
  SeededRng rng(20);
  const int n = model_.nq();
  const VectorX zero = VectorX::Zero(n);
  const Vector3 p_WS(0.1, -0.2, -0.3);
  for (int k = 0; k < kStates; ++k) {
    const VectorX q = rng.uniform_vector(n, -3, 3);
    rnea(model_, data, q, zero, zero);
    const Vector6 reading = sensor_reading_world(data, p_WS);
    // Independent centre of mass: from the model's inertias and the body poses (rnea forms none).
    forward_poses(model_, data, q);
    double m = 0;
    Vector3 mc = Vector3::Zero();
    for (int i = 0; i <= n; ++i) {
      const Inertia& in = model_.bodies[i].inertia;
      m += in.mass;
      mc += in.mass * data.X_WB[i].act(in.com);
    }
    const Vector3 weight = m * model_.gravity;
    EXPECT_LE((reading.head<3>() - weight).norm(), 1e-12 * weight.norm());
    EXPECT_LE((reading.tail<3>() - (mc / m - p_WS).cross(weight)).norm(), 1e-12 * weight.norm());
  }
}

// The condition number of Fig. 10, against the SVD of the same columns computed here: for every
// body of random chains (l < 6 takes the Gram matrix Jᵀ J, l ≥ 6 J Jᵀ), and at the stretched
// paper arm's singularity (κ far above 1e6, where the SVD is used).
TEST(JacobianCondition, EqualsTheRatioOfTheSingularValues) {
  SeededRng rng(31);
  for (const int n : {3, 5, 7, 9}) {
    const Model model = random_chain({n, false, false, static_cast<std::uint64_t>(40 + n)});
    Data data(model);
    Matrix6X J(6, n);
    for (int k = 0; k < 50; ++k) {
      forward_poses(model, data, rng.uniform_vector(n, -3, 3));
      for (int body = 1; body <= n; ++body) {
        point_jacobian(model, data, body, data.X_WB[body].translation, J);
        const Eigen::JacobiSVD<MatrixX> svd(J.leftCols(body));
        const auto& s = svd.singularValues();
        const double expected = s[0] / s[s.size() - 1];
        const double got = jacobian_condition(model, data, body);
        if (expected < 1e6) {
          EXPECT_NEAR(got, expected, 1e-8 * expected) << "n " << n << " body " << body;
        } else {
          EXPECT_GT(got, 1e5) << "n " << n << " body " << body;
        }
      }
    }
  }
  const Model arm = paper_arm();
  Data data(arm);
  forward_poses(arm, data, VectorX::Zero(arm.nq()));
  EXPECT_GT(jacobian_condition(arm, data, arm.nq()), 1e6);
  EXPECT_TRUE(std::isnan(jacobian_condition(arm, data, 0)));
}

INSTANTIATE_TEST_SUITE_P(RandomModels, DynamicsIdentities,
                         ::testing::Values(Case{"Chain7", {7, false, false, 1}},
                                           Case{"Tree9", {9, true, false, 2}},
                                           Case{"ChainWithPrismatic6", {6, false, true, 3}},
                                           Case{"TreeWithPrismatic8", {8, true, true, 4}}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace extwrench
