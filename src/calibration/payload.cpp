// Payload identification from the base wrench (docs/calibration.md#payload): the reading of a
// base F/T sensor is linear in the payload's mass m and first moment h = m c (c its CoM in the
// last link's frame) once its rotational inertia about the link origin is neglected, and the
// sensor bias adds a constant; so [m, h, bias] is one linear least-squares problem over the log.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "payload_fit.hpp"

namespace extwrench::calibration_detail {
namespace {

// Central difference of q̇ over ±kHalfWidth samples: q̈ for the payload's inertial terms.
constexpr std::size_t kHalfWidth = 5;

// A body carrying only a first moment h (mass 1 at h, rotational inertia about the body origin
// zero): the column of h minus that of the unit mass at the origin.
Inertia unit_first_moment(const Vector3& h) {
  Inertia in;
  in.mass = 1.0;
  in.com = h;
  in.inertia_com = -(h.squaredNorm() * Matrix3::Identity() - h * h.transpose());
  return in;
}

}  // namespace

PayloadFit fit_payload(const Model& model, const Pose& X_WS, int body,
                       const std::vector<Sample>& samples, const std::vector<char>& use) {
  const int n = model.nq();
  if (body < 1 || body > n) throw Error("payload: body " + std::to_string(body) + " out of range");
  // Five models: as given, + unit mass at the origin, + unit first moment along x, y, z.
  std::vector<Model> models(5, model);
  Inertia unit;
  unit.mass = 1.0;
  auto& b1 = models[1].bodies[static_cast<std::size_t>(body)].inertia;
  b1 = b1 + unit;
  for (int a = 0; a < 3; ++a) {
    auto& b =
        models[static_cast<std::size_t>(2 + a)].bodies[static_cast<std::size_t>(body)].inertia;
    b = b + unit_first_moment(Vector3::Unit(a));
  }
  std::vector<Data> data;
  data.reserve(5);
  for (const Model& m : models) data.emplace_back(m);
  constexpr int kParams = 10;  // m, h (3), bias [f; n] (6)
  Eigen::Matrix<double, kParams, kParams> AtA = Eigen::Matrix<double, kParams, kParams>::Zero();
  Eigen::Matrix<double, kParams, 1> Aty = Eigen::Matrix<double, kParams, 1>::Zero();
  double yy = 0.0;
  std::size_t rows = 0;
  VectorX ddq(n);
  Eigen::Matrix<double, 6, kParams> A;
  std::vector<Vector6> y_all;
  std::vector<Eigen::Matrix<double, 6, kParams>> a_all;
  const std::size_t N = samples.size();
  for (std::size_t k = kHalfWidth; k + kHalfWidth < N; ++k) {
    if (!use[k]) continue;
    const Sample& lo = samples[k - kHalfWidth];
    const Sample& hi = samples[k + kHalfWidth];
    ddq = (hi.dq - lo.dq) / (hi.t - lo.t);
    const Sample& s = samples[k];
    Vector6 r[5];
    for (std::size_t j = 0; j < 5; ++j) {
      (void)rnea(models[j], data[j], s.q, s.dq, ddq);
      r[j] = sensor_reading(data[j], X_WS);
    }
    A.col(0) = r[1] - r[0];
    for (int a = 0; a < 3; ++a) A.col(1 + a) = r[2 + a] - r[1];
    A.rightCols<6>().setIdentity();
    const Vector6 y = s.reading_S - r[0];
    AtA.noalias() += A.transpose() * A;
    Aty.noalias() += A.transpose() * y;
    yy += y.squaredNorm();
    y_all.push_back(y);
    a_all.push_back(A);
    ++rows;
  }
  if (rows < 2 * kParams) {
    throw Error("payload: " + std::to_string(rows) + " samples for " + std::to_string(kParams) +
                " parameters: record a longer motion");
  }
  // Column scaling for the condition number.
  const Eigen::Matrix<double, kParams, 1> scale = AtA.diagonal().cwiseSqrt().cwiseMax(1e-12);
  const Eigen::Matrix<double, kParams, kParams> S = scale.cwiseInverse().asDiagonal();
  const Eigen::Matrix<double, kParams, kParams> N_scaled = S * AtA * S;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kParams, kParams>> eig(N_scaled);
  PayloadFit fit;
  fit.condition =
      std::sqrt(eig.eigenvalues().maxCoeff() / std::max(eig.eigenvalues().minCoeff(), 1e-300));
  const Eigen::Matrix<double, kParams, 1> theta = S * N_scaled.ldlt().solve(S * Aty);
  fit.mass = theta[0];
  fit.first_moment = theta.segment<3>(1);
  fit.bias_S = theta.tail<6>();
  // RMS of the sensor's prediction error per axis with only the bias, and with the payload too.
  Vector6 before = Vector6::Zero(), after = Vector6::Zero();
  Vector6 mean_y = Vector6::Zero();
  for (const Vector6& y : y_all) mean_y += y;
  mean_y /= static_cast<double>(rows);
  for (std::size_t k = 0; k < rows; ++k) {
    before += (y_all[k] - mean_y).cwiseAbs2();
    after += (y_all[k] - a_all[k] * theta).cwiseAbs2();
  }
  fit.rms_before = (before / static_cast<double>(rows)).cwiseSqrt();
  fit.rms_after = (after / static_cast<double>(rows)).cwiseSqrt();
  fit.samples = static_cast<int>(rows);
  (void)yy;
  if (fit.condition > 1e6) {
    throw Error("payload: mass and centre of mass not excited (condition " +
                std::to_string(fit.condition) +
                "): record a motion that accelerates the last link and turns it in gravity");
  }
  if (!(fit.mass > 0.0)) {
    throw Error("payload: identified mass " + std::to_string(fit.mass) +
                " kg is not positive: no payload on the last link, or a model or sensor pose "
                "error; run without --payload");
  }
  return fit;
}

}  // namespace extwrench::calibration_detail
