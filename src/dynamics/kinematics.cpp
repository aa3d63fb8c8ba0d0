#include "extwrench/dynamics/kinematics.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "argument_checks.hpp"
#include "spatial.hpp"

namespace extwrench {
namespace {

/// σ_max / σ_min of J by its SVD (+inf when singular).
template <typename Derived>
double svd_condition(const Eigen::MatrixBase<Derived>& J) {
  Eigen::JacobiSVD<MatrixX> svd(J);
  const auto& sv = svd.singularValues();
  const double smin = sv[sv.size() - 1];
  return smin > 0.0 ? sv[0] / smin : std::numeric_limits<double>::infinity();
}

}  // namespace

void forward_kinematics(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  detail::check_data("forward_kinematics", model, data);
  detail::check_joint_vector("forward_kinematics", "q", q.size(), model);
  detail::poses_and_subspaces(model, data, q);
  world_mass_properties(model, data);
}

void forward_poses(const Model& model, Data& data, const Eigen::Ref<const VectorX>& q) {
  detail::check_data("forward_poses", model, data);
  detail::check_joint_vector("forward_poses", "q", q.size(), model);
  detail::poses_and_subspaces(model, data, q);
}

void world_mass_properties(const Model& model, Data& data) {
  const int nb = model.num_bodies();
  for (int i = 0; i < nb; ++i) detail::world_mass_properties_of(model, data, i);
}

Pose frame_pose(const Model& model, const Data& data, int frame) {
  detail::check_data("frame_pose", model, data);
  if (frame < 0 || frame >= static_cast<int>(model.frames.size())) [[unlikely]]
    detail::argument_error("frame_pose", "frame " + std::to_string(frame) +
                                             " is not a frame of the model (0.." +
                                             std::to_string(model.frames.size() - 1) + ")");
  const Frame& fr = model.frames[static_cast<std::size_t>(frame)];
  return data.X_WB[fr.body] * fr.placement;
}

void point_jacobian(const Model& model, const Data& data, int body, const Vector3& p_W,
                    Eigen::Ref<Matrix6X> J) {
  detail::check_body("point_jacobian", "body", body, model);
  if (J.cols() != model.nq()) [[unlikely]]
    detail::argument_error("point_jacobian", "J has " + std::to_string(J.cols()) +
                                                 " columns, the model has " +
                                                 std::to_string(model.nq()) + " joints");
  J.setZero();
  // Point velocity = v_O + w x p: column j = [S_lin + S_ang x p; S_ang] for the ancestors j.
  for (int j = body; j > 0; j = model.parents[j]) {
    const Vector6& s = data.S[j];
    J.col(j - 1).head<3>() = s.head<3>() + s.tail<3>().cross(p_W);
    J.col(j - 1).tail<3>() = s.tail<3>();
  }
}

const Matrix6X& body_jacobian(const Model& model, Data& data, int body) {
  detail::check_body("body_jacobian", "body", body, model);
  point_jacobian(model, data, body, data.X_WB[body].translation, data.J);
  return data.J;
}

double jacobian_condition(const Model& model, const Data& data, int body) {
  if (body <= 0) return std::numeric_limits<double>::quiet_NaN();
  // Columns 1..l (Remark 1: the others are zero for a chain).
  constexpr int kMaxColumns = 64;
  if (model.nq() > kMaxColumns) {
    Matrix6X J(6, model.nq());
    point_jacobian(model, data, body, data.X_WB[static_cast<std::size_t>(body)].translation, J);
    return svd_condition(J.leftCols(body));
  }
  Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxColumns> J(6, model.nq());
  point_jacobian(model, data, body, data.X_WB[static_cast<std::size_t>(body)].translation, J);
  // σ² are the eigenvalues of the smaller Gram matrix (J Jᵀ, or Jᵀ J for l < 6): far cheaper
  // than an SVD, and accurate to ~1e-16 κ² relative, so used while κ < 1e6; nearer a
  // singularity (the peaks of Fig. 10) the SVD.
  using Gram = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  const auto Jl = J.leftCols(body);
  const Gram gram = body >= 6 ? Gram(Jl * Jl.transpose()) : Gram(Jl.transpose() * Jl);
  const Eigen::SelfAdjointEigenSolver<Gram> eig(gram, Eigen::EigenvaluesOnly);
  const double lambda_min = eig.eigenvalues()[0];
  const double lambda_max = eig.eigenvalues()[eig.eigenvalues().size() - 1];
  if (eig.info() == Eigen::Success && lambda_max > 0.0 && lambda_min > 1e-12 * lambda_max)
    return std::sqrt(lambda_max / lambda_min);
  return svd_condition(Jl);
}

}  // namespace extwrench
