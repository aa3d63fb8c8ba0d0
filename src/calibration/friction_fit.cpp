#include "friction_fit.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/observer/residual_filter.hpp"

namespace extwrench::calibration_detail {
namespace {

// Grid of Coulomb smoothing velocities [rad/s] and sigmoid shifts [rad/s] searched per joint.
constexpr std::array kSmoothingGrid{0.002, 0.005, 0.01, 0.02, 0.03, 0.05,
                                    0.075, 0.1,   0.15, 0.2,  0.3,  0.5};
constexpr std::array kShiftGrid{-0.05, -0.04, -0.03, -0.02, -0.01, 0.0,
                                0.01,  0.02,  0.03,  0.04,  0.05};
// Motion needed to identify friction: a peak speed, and a share of the samples each way.
constexpr double kMinPeakSpeed = 0.05;     // [rad/s]
constexpr double kMinShareEachWay = 0.02;  // of the samples used
constexpr double kMaxCondition = 1e4;      // of the column-scaled regression

std::string joint_name(int joint) { return "joint " + std::to_string(joint); }

// Least squares of r⁰ + Z θ ≈ 0 over the used samples, with the columns in `active`.
struct Solve {
  Eigen::Vector3d theta = Eigen::Vector3d::Zero();
  double rss = std::numeric_limits<double>::infinity();
  double condition = 1.0;
};

Solve solve(const std::array<const std::vector<double>*, 3>& z, const std::vector<double>& r0,
            const std::vector<char>& use, const std::array<bool, 3>& active, double lambda) {
  Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double rr = 0.0;
  for (std::size_t k = 0; k < r0.size(); ++k) {
    if (!use[k]) continue;
    const Eigen::Vector3d zk((*z[0])[k], (*z[1])[k], (*z[2])[k]);
    G.noalias() += zk * zk.transpose();
    b.noalias() -= zk * r0[k];
    rr += r0[k] * r0[k];
  }
  Solve out;
  Eigen::Vector3d scale = Eigen::Vector3d::Zero();
  for (int c = 0; c < 3; ++c)
    scale[c] = active[static_cast<std::size_t>(c)] && G(c, c) > 0 ? 1.0 / std::sqrt(G(c, c)) : 0.0;
  Eigen::Matrix3d Gs = scale.asDiagonal() * G * scale.asDiagonal();
  for (int c = 0; c < 3; ++c)
    if (scale[c] == 0.0) Gs(c, c) = 1.0;  // an inactive column: θ_c = 0
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(Gs);
  const Eigen::Vector3d ev = eig.eigenvalues();
  out.condition = std::sqrt(std::max(ev.maxCoeff(), 0.0) / std::max(ev.minCoeff(), 1e-300));
  Gs.diagonal().array() += lambda * Gs.trace() / 3.0;
  const Eigen::Vector3d bs = scale.asDiagonal() * b;
  out.theta = scale.asDiagonal() * Gs.ldlt().solve(bs);
  // RSS = rᵀr + 2 θᵀ Zᵀr + θᵀ G θ with Zᵀr = −b.
  out.rss = rr - 2.0 * out.theta.dot(b) + out.theta.dot(G * out.theta);
  return out;
}

}  // namespace

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y,
                 const std::vector<char>& use) {
  LineFit f;
  double sx = 0.0, sy = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    if (!use[k]) continue;
    f.count += 1.0;
    sx += x[k];
    sy += y[k];
  }
  if (f.count < 1.0) return f;
  f.mean_x = sx / f.count;
  f.mean_y = sy / f.count;
  for (std::size_t k = 0; k < y.size(); ++k) {
    if (!use[k]) continue;
    const double dx = x[k] - f.mean_x, dy = y[k] - f.mean_y;
    f.sxx += dx * dx;
    f.sxy += dx * dy;
    f.syy += dy * dy;
  }
  f.intercept = f.mean_y;
  if (f.count < 3.0 || f.sxx <= 1e-300) return f;
  f.slope = f.sxy / f.sxx;
  f.intercept = f.mean_y - f.slope * f.mean_x;
  if (f.syy > 1e-300) f.r2 = f.sxy * f.sxy / (f.sxx * f.syy);
  return f;
}

void filter_regressor(const std::vector<double>& phi, const std::vector<double>& alpha,
                      std::vector<double>& z, const std::vector<double>& residual_filter_weight) {
  z.assign(phi.size(), 0.0);
  for (std::size_t k = 1; k < phi.size(); ++k)
    z[k] = alpha[k] * z[k - 1] + (1.0 - alpha[k]) * 0.5 * (phi[k - 1] + phi[k]);
  apply_residual_filter(residual_filter_weight, z);
}

std::vector<double> residual_filter_weights(const std::vector<Sample>& samples, double cutoff) {
  std::vector<double> weight(samples.size(), 0.0);
  for (std::size_t k = 1; k < samples.size(); ++k)
    weight[k] = residual_filter_weight(cutoff, samples[k].t - samples[k - 1].t);
  return weight;
}

void apply_residual_filter(const std::vector<double>& weight, std::vector<double>& x) {
  if (weight.empty()) return;
  double s1 = 0.0, s2 = 0.0;
  for (std::size_t k = 1; k < x.size(); ++k) x[k] = residual_filter_step(weight[k], x[k], s1, s2);
}

void check_excitation(const JointSeries& s, const std::vector<char>& use, int joint,
                      double smoothing) {
  double peak = 0.0;
  std::size_t up = 0, down = 0, used = 0;
  for (std::size_t k = 0; k < s.dq.size(); ++k) {
    if (!use[k]) continue;
    ++used;
    peak = std::max(peak, std::abs(s.dq[k]));
    if (s.dq[k] > smoothing) ++up;
    if (s.dq[k] < -smoothing) ++down;
  }
  const std::string j = joint_name(joint);
  if (peak < kMinPeakSpeed) {
    throw Error(j + ": viscous and Coulomb friction not excited: |dq" + std::to_string(joint) +
                "| stays below " + std::to_string(peak) + " rad/s; record a motion that moves " +
                j + " back and forth at 0.2 rad/s or more");
  }
  const double share_up = static_cast<double>(up) / static_cast<double>(used);
  const double share_down = static_cast<double>(down) / static_cast<double>(used);
  if (share_up < kMinShareEachWay || share_down < kMinShareEachWay) {
    throw Error(j + ": Coulomb friction not excited: " + j + " moves faster than " +
                std::to_string(smoothing) + " rad/s in the positive direction on " +
                std::to_string(100.0 * share_up) + " % and in the negative direction on " +
                std::to_string(100.0 * share_down) +
                " % of the samples; record a motion that moves it both ways");
  }
}

JointFrictionFit fit_joint(const JointSeries& s, const std::vector<char>& use,
                           const CalibrationOptions& options, int joint) {
  const std::size_t N = s.dq.size();
  std::vector<double> ones(N, 1.0), z_viscous, z_offset, phi(N), z_coulomb;
  filter_regressor(s.dq, s.alpha, z_viscous, s.filter_weight);
  filter_regressor(ones, s.alpha, z_offset, s.filter_weight);
  std::vector<double> smoothings(kSmoothingGrid.begin(), kSmoothingGrid.end());
  if (options.smoothing_velocity > 0) smoothings = {options.smoothing_velocity};
  std::vector<double> shifts{0.0};
  if (options.sign == SmoothSign::kSigmoid) shifts.assign(kShiftGrid.begin(), kShiftGrid.end());

  JointFrictionFit best;
  Solve best_solve;
  for (const double vs : smoothings) {
    for (const double shift : shifts) {
      for (std::size_t k = 0; k < N; ++k) phi[k] = smooth_sign(options.sign, s.dq[k], vs, shift);
      filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
      std::array<bool, 3> active{true, true, true};
      Solve sol =
          solve({&z_viscous, &z_coulomb, &z_offset}, s.r0, use, active, options.regularisation);
      // Friction opposes motion: a negative coefficient is dropped and the rest refitted.
      for (int c = 0; c < 2 && (sol.theta[0] < 0 || sol.theta[1] < 0); ++c) {
        if (sol.theta[0] < 0) active[0] = false;
        if (sol.theta[1] < 0) active[1] = false;
        sol = solve({&z_viscous, &z_coulomb, &z_offset}, s.r0, use, active, options.regularisation);
      }
      if (sol.rss < best_solve.rss) {
        best_solve = sol;
        best.smoothing = vs;
        best.shift = shift;
      }
    }
  }
  const std::string j = joint_name(joint);
  if (best_solve.condition > kMaxCondition) {
    throw Error(j + ": viscous friction, Coulomb friction and offset cannot be told apart " +
                "(condition " + std::to_string(best_solve.condition) + "); record a motion of " +
                j + " with slow and fast phases in both directions");
  }
  best.viscous = best_solve.theta[0];
  best.coulomb = best_solve.theta[1];
  best.offset = best_solve.theta[2];
  best.condition = best_solve.condition;
  if (best.viscous == 0.0) best.warnings.push_back(j + ": viscous friction fitted < 0, set to 0");
  if (best.coulomb == 0.0) best.warnings.push_back(j + ": Coulomb friction fitted < 0, set to 0");
  // The residual with the chosen friction, over the whole log.
  for (std::size_t k = 0; k < N; ++k)
    phi[k] = smooth_sign(options.sign, s.dq[k], best.smoothing, best.shift);
  filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
  best.residual.resize(N);
  for (std::size_t k = 0; k < N; ++k)
    best.residual[k] = s.r0[k] + best.viscous * z_viscous[k] + best.coulomb * z_coulomb[k] +
                       best.offset * z_offset[k];
  return best;
}

}  // namespace extwrench::calibration_detail
