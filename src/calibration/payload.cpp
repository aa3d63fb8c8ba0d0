// Payload identification from the base wrench and the joint torques together
// (docs/calibration.md#payload): the reading of a base sensor and the joint torques are linear
// in the payload's mass m and first moment h = m c (c its CoM in the last link's frame) once its
// rotational inertia about the link origin is neglected; the sensor bias adds a constant, the
// joints' friction and offsets their own terms; so [m, h, bias, friction] is one linear
// least-squares problem over the log.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "friction_fit.hpp"
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

PayloadFit fit_payload(const Model& model, const Pose& X_WS, int body, bool moments,
                       double smoothing_velocity, const std::vector<Sample>& samples,
                       const std::vector<char>& use) {
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
  // Unknowns: m, h (3), the bias (6 or 3), and per joint viscous, Coulomb, offset.
  const int axes = moments ? 6 : 3;
  const int first_friction = 4 + axes;
  const int params = first_friction + 3 * n;
  // One row group per sensor axis and per joint: its normal equations, Σy and Σy², so that
  // each group's misfit for any θ comes from sums alone (no rows are kept).
  const int groups = axes + n;
  std::vector<MatrixX> AtA(static_cast<std::size_t>(groups), MatrixX::Zero(params, params));
  std::vector<VectorX> Aty(static_cast<std::size_t>(groups), VectorX::Zero(params));
  std::vector<double> yy(static_cast<std::size_t>(groups), 0.0);
  std::vector<double> ysum(static_cast<std::size_t>(groups), 0.0);
  std::size_t rows = 0;
  VectorX ddq(n), row(params);
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
    const auto add = [&](int g, double y) {
      const auto gi = static_cast<std::size_t>(g);
      AtA[gi].selfadjointView<Eigen::Lower>().rankUpdate(row);
      Aty[gi].noalias() += y * row;
      yy[gi] += y * y;
      ysum[gi] += y;
    };
    for (int a = 0; a < axes; ++a) {
      row.setZero();
      row[0] = r[1][a] - r[0][a];
      for (int c = 0; c < 3; ++c) row[1 + c] = r[2 + c][a] - r[1][a];
      row[4 + a] = 1.0;
      add(a, s.reading_S[a] - r[0][a]);
    }
    for (int i = 0; i < n; ++i) {
      row.setZero();
      row[0] = data[1].tau[i] - data[0].tau[i];
      for (int c = 0; c < 3; ++c) row[1 + c] = data[2 + c].tau[i] - data[1].tau[i];
      row[first_friction + 3 * i] = s.dq[i];
      row[first_friction + 3 * i + 1] = std::tanh(s.dq[i] / smoothing_velocity);
      row[first_friction + 3 * i + 2] = 1.0;
      add(axes + i, s.tau[i] - data[0].tau[i]);
    }
    ++rows;
  }
  if (rows < static_cast<std::size_t>(params)) {
    throw Error("payload: " + std::to_string(rows) + " samples for " + std::to_string(params) +
                " parameters: record a longer motion");
  }
  for (MatrixX& m : AtA) m = m.selfadjointView<Eigen::Lower>();
  const auto misfit = [&](int g, const VectorX& theta) {  // Σ (y − aᵀθ)² of group g
    const auto gi = static_cast<std::size_t>(g);
    return std::max(yy[gi] - 2.0 * theta.dot(Aty[gi]) + theta.dot(AtA[gi] * theta), 0.0);
  };
  // Two passes: unit weights, then each group by the inverse of its first-pass misfit's RMS
  // (sensor axes in N and N m, joints in N m: each measured against its own noise).
  std::vector<double> weight(static_cast<std::size_t>(groups), 1.0);
  PayloadFit fit;
  VectorX theta(params);
  for (int pass = 0; pass < 2; ++pass) {
    MatrixX normal = MatrixX::Zero(params, params);
    VectorX rhs = VectorX::Zero(params);
    for (int g = 0; g < groups; ++g) {
      normal += weight[static_cast<std::size_t>(g)] * AtA[static_cast<std::size_t>(g)];
      rhs += weight[static_cast<std::size_t>(g)] * Aty[static_cast<std::size_t>(g)];
    }
    // Column scaling for the condition number.
    const VectorX scale = normal.diagonal().cwiseSqrt().cwiseMax(1e-12);
    const MatrixX S = scale.cwiseInverse().asDiagonal();
    const MatrixX scaled = S * normal * S;
    Eigen::SelfAdjointEigenSolver<MatrixX> eig(scaled);
    fit.condition =
        std::sqrt(eig.eigenvalues().maxCoeff() / std::max(eig.eigenvalues().minCoeff(), 1e-300));
    theta = S * scaled.ldlt().solve(S * rhs);
    for (int g = 0; g < groups; ++g) {
      const double rms = std::sqrt(misfit(g, theta) / static_cast<double>(rows));
      weight[static_cast<std::size_t>(g)] = 1.0 / std::max(rms * rms, 1e-12);
    }
  }
  fit.mass = theta[0];
  fit.first_moment = theta.segment<3>(1);
  fit.bias_S.head(axes) = theta.segment(4, axes);
  // RMS per sensor axis and joint with the bias (and friction) only, and with the payload too.
  VectorX no_payload = theta;
  no_payload.head<4>().setZero();
  const auto rms = [&](int g, const VectorX& th) {
    return std::sqrt(misfit(g, th) / static_cast<double>(rows));
  };
  for (int a = 0; a < axes; ++a) {
    // Before: the spread about the mean (the bias alone absorbs the mean).
    const auto gi = static_cast<std::size_t>(a);
    const double mean = ysum[gi] / static_cast<double>(rows);
    fit.rms_before[a] = std::sqrt(std::max(yy[gi] / static_cast<double>(rows) - mean * mean, 0.0));
    fit.rms_after[a] = rms(a, theta);
  }
  fit.joint_rms_before = VectorX::Zero(n);
  fit.joint_rms_after = VectorX::Zero(n);
  for (int i = 0; i < n; ++i) {
    fit.joint_rms_before[i] = rms(axes + i, no_payload);
    fit.joint_rms_after[i] = rms(axes + i, theta);
  }
  fit.samples = static_cast<int>(rows);
  if (fit.condition > 1e6) {
    throw Error("payload: mass and centre of mass not excited (condition " +
                number_text(fit.condition, 3) +
                "): record a motion that accelerates the last link and turns it in gravity");
  }
  if (!(fit.mass > 0.0)) {
    throw Error("payload: identified mass " + number_text(fit.mass) +
                " kg is not positive: no payload on the last link, or a model or sensor pose "
                "error; run without --payload");
  }
  return fit;
}

}  // namespace extwrench::calibration_detail
