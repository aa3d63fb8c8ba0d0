#include "friction_fit.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <tuple>
#include <utility>

#include "extwrench/core/error.hpp"
#include "extwrench/observer/residual_filter.hpp"

namespace extwrench::calibration_detail {
namespace {

// Grid of Coulomb smoothing velocities [rad/s] and sigmoid shifts [rad/s] searched per joint.
constexpr std::array kSmoothingGrid{0.002, 0.005, 0.01, 0.02, 0.03, 0.05,
                                    0.075, 0.1,   0.15, 0.2,  0.3,  0.5};
// Presliding displacements of the Dahl sign [rad]: a harmonic drive's stays within ~0.01 rad
// (larger ones would fit slow parts of the motion, not the reversals).
constexpr std::array kPreslidingGrid{0.0005, 0.001, 0.002, 0.003, 0.005, 0.007, 0.01};
constexpr std::array kShiftGrid{-0.05, -0.04, -0.03, -0.02, -0.01, 0.0,
                                0.01,  0.02,  0.03,  0.04,  0.05};
// Motion needed to identify friction: a peak speed, and a share of the samples each way.
constexpr double kMinPeakSpeed = 0.05;     // [rad/s]
constexpr double kMinShareEachWay = 0.02;  // of the samples used
constexpr double kMaxCondition = 1e4;      // of the column-scaled regression
// The inertia correction is fitted where it lowers the residual's sum of squares by this share.
constexpr double kMinInertiaGain = 0.1;

std::string joint_name(int joint) { return "joint " + std::to_string(joint); }

// The Coulomb term's regressor φ_k: the smooth sign of q̇_k, or the Dahl state over the joint's
// positions from z = 0 at the first sample (as the observer after a reset), with `scale` = v_s
// or δ.
void coulomb_regressor(const JointSeries& s, SmoothSign sign, double scale, double shift,
                       std::vector<double>& phi) {
  const std::size_t N = s.dq.size();
  phi.resize(N);
  if (sign != SmoothSign::kDahl) {
    for (std::size_t k = 0; k < N; ++k) phi[k] = smooth_sign(sign, s.dq[k], scale, shift);
    return;
  }
  double z = 0.0;
  for (std::size_t k = 0; k < N; ++k) {
    if (k > 0) z = dahl_step(z, s.q[k] - s.q[k - 1], scale);
    phi[k] = z;
  }
}

// Least squares of r⁰ + Z θ ≈ 0 over the used samples, with the C columns in `active`.
template <int C>
struct Solve {
  using Vec = Eigen::Matrix<double, C, 1>;
  Vec theta = Vec::Zero();
  double rss = std::numeric_limits<double>::infinity();
  double condition = 1.0;
  double rr = 0.0,
         count = 0.0;  ///< the residual's sum of squares without friction, and its samples
};

template <int C>
Solve<C> solve(const std::array<const std::vector<double>*, C>& z, const std::vector<double>& r0,
               const std::vector<char>& use, const std::array<bool, C>& active, double lambda) {
  using Mat = Eigen::Matrix<double, C, C>;
  using Vec = Eigen::Matrix<double, C, 1>;
  Mat G = Mat::Zero();
  Vec b = Vec::Zero();
  double rr = 0.0, count = 0.0;
  for (std::size_t k = 0; k < r0.size(); ++k) {
    if (!use[k]) continue;
    count += 1.0;
    Vec zk;
    for (int c = 0; c < C; ++c) zk[c] = (*z[static_cast<std::size_t>(c)])[k];
    G.noalias() += zk * zk.transpose();
    b.noalias() -= zk * r0[k];
    rr += r0[k] * r0[k];
  }
  Solve<C> out;
  out.rr = rr;
  out.count = count;
  Vec scale = Vec::Zero();
  for (int c = 0; c < C; ++c)
    scale[c] = active[static_cast<std::size_t>(c)] && G(c, c) > 0 ? 1.0 / std::sqrt(G(c, c)) : 0.0;
  Mat Gs = scale.asDiagonal() * G * scale.asDiagonal();
  for (int c = 0; c < C; ++c)
    if (scale[c] == 0.0) Gs(c, c) = 1.0;  // an inactive column: θ_c = 0
  const Eigen::SelfAdjointEigenSolver<Mat> eig(Gs);
  const Vec ev = eig.eigenvalues();
  out.condition = std::sqrt(std::max(ev.maxCoeff(), 0.0) / std::max(ev.minCoeff(), 1e-300));
  Gs.diagonal().array() += lambda * Gs.trace() / C;
  const Vec bs = scale.asDiagonal() * b;
  out.theta = scale.asDiagonal() * Gs.ldlt().solve(bs);
  // RSS = rᵀr + 2 θᵀ Zᵀr + θᵀ G θ with Zᵀr = −b.
  out.rss = rr - 2.0 * out.theta.dot(b) + out.theta.dot(G * out.theta);
  return out;
}

// Columns D, F_c, o first, then any others (gravity, inertia correction): solved, a negative
// friction coefficient dropped and the rest refitted (friction opposes motion).
template <int C>
Solve<C> solve_friction(const std::array<const std::vector<double>*, C>& z,
                        const std::vector<double>& r0, const std::vector<char>& use,
                        double lambda) {
  std::array<bool, C> active;
  active.fill(true);
  Solve<C> sol = solve<C>(z, r0, use, active, lambda);
  for (int c = 0; c < 2 && (sol.theta[0] < 0 || sol.theta[1] < 0); ++c) {
    if (sol.theta[0] < 0) active[0] = false;
    if (sol.theta[1] < 0) active[1] = false;
    sol = solve<C>(z, r0, use, active, lambda);
  }
  return sol;
}

// Sum of squares and largest |r| of r⁰ + D z_D + F_c z_c + o z_o over the used samples.
std::pair<double, double> residual_size(const std::vector<double>& r0, const Eigen::Vector3d& theta,
                                        const std::vector<double>& z_viscous,
                                        const std::vector<double>& z_coulomb,
                                        const std::vector<double>& z_offset,
                                        const std::vector<char>& use) {
  double rss = 0.0, peak = 0.0;
  for (std::size_t k = 0; k < r0.size(); ++k) {
    if (!use[k]) continue;
    const double r =
        r0[k] + theta[0] * z_viscous[k] + theta[1] * z_coulomb[k] + theta[2] * z_offset[k];
    rss += r * r;
    peak = std::max(peak, std::abs(r));
  }
  return {rss, peak};
}

// The friction fit with the sign (θ, v_s, shift given) beside the best one with the Dahl sign.
DahlAlternative dahl_alternative(const JointSeries& s, const std::vector<char>& use,
                                 double regularisation, const Eigen::Vector3d& sign_theta,
                                 double smoothing, double shift, SmoothSign sign,
                                 const std::vector<double>& z_viscous,
                                 const std::vector<double>& z_offset) {
  DahlAlternative out;
  std::vector<double> phi, z_coulomb;
  coulomb_regressor(s, sign, smoothing, shift, phi);
  filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
  std::tie(out.sign_rss, out.sign_peak) =
      residual_size(s.r0, sign_theta, z_viscous, z_coulomb, z_offset, use);
  Solve<3> best;
  for (const double delta : kPreslidingGrid) {
    coulomb_regressor(s, SmoothSign::kDahl, delta, 0.0, phi);
    filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
    const Solve<3> sol =
        solve_friction<3>({&z_viscous, &z_coulomb, &z_offset}, s.r0, use, regularisation);
    if (sol.rss >= best.rss) continue;
    best = sol;
    out.presliding = delta;
  }
  coulomb_regressor(s, SmoothSign::kDahl, out.presliding, 0.0, phi);
  filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
  std::tie(out.rss, out.peak) =
      residual_size(s.r0, best.theta, z_viscous, z_coulomb, z_offset, use);
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

std::vector<double> fast_part(const std::vector<double>& x, const std::vector<Sample>& samples,
                              double window) {
  const std::size_t N = x.size();
  std::vector<double> prefix(N + 1, 0.0);
  for (std::size_t k = 0; k < N; ++k) prefix[k + 1] = prefix[k] + x[k];
  std::vector<double> out(N);
  std::size_t lo = 0, hi = 0;  // the window is [lo, hi)
  for (std::size_t k = 0; k < N; ++k) {
    const double t = samples[k].t;
    while (samples[lo].t < t - 0.5 * window) ++lo;
    while (hi < N && samples[hi].t <= t + 0.5 * window) ++hi;
    out[k] = x[k] - (prefix[hi] - prefix[lo]) / static_cast<double>(hi - lo);
  }
  return out;
}

std::string number_text(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, value == 0.0 ? 0.0 : value);  // no "-0"
  return text;
}

std::vector<double> central_acceleration(const JointSeries& s) {
  const std::size_t N = s.dq.size();
  std::vector<double> acceleration(N, 0.0);
  for (std::size_t k = 1; k + 1 < N; ++k)
    acceleration[k] = (s.dq[k + 1] - s.dq[k - 1]) / (s.dt[k] + s.dt[k + 1]);
  return acceleration;
}

bool inertia_aliases_gravity(const JointSeries& s, const std::vector<double>& acceleration,
                             const std::vector<char>& use, double& correlation) {
  constexpr double kAliasCorrelation = 0.95;
  correlation = 0.0;
  const std::size_t N = s.dq.size();
  if (s.axis_along_gravity || N < 3 || s.q.size() != N || acceleration.size() != N ||
      use.size() != N)
    return false;
  std::vector<char> inner(use);  // the used samples with a central difference
  inner[0] = inner[N - 1] = 0;
  const LineFit a = fit_line(s.q, acceleration, inner);
  if (a.sxx <= 1e-300 || a.syy <= 1e-300) return false;
  correlation = a.sxy / std::sqrt(a.sxx * a.syy);
  return std::abs(correlation) >= kAliasCorrelation;
}

void filter_regressor(const std::vector<double>& phi, const std::vector<double>& alpha,
                      std::vector<double>& z, const std::vector<double>& residual_filter_weight) {
  z.assign(phi.size(), 0.0);
  for (std::size_t k = 1; k < phi.size(); ++k)
    z[k] = alpha[k] * z[k - 1] + (1.0 - alpha[k]) * 0.5 * (phi[k - 1] + phi[k]);
  apply_residual_filter(residual_filter_weight, z);
}

void filter_rate(const std::vector<double>& x, const std::vector<double>& alpha,
                 const std::vector<double>& dt, std::vector<double>& z,
                 const std::vector<double>& residual_filter_weight) {
  z.assign(x.size(), 0.0);
  for (std::size_t k = 1; k < x.size(); ++k)
    z[k] = alpha[k] * z[k - 1] + (1.0 - alpha[k]) * (x[k] - x[k - 1]) / dt[k];
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
                "| stays below " + number_text(peak) + " rad/s; record a motion that moves " + j +
                " back and forth at 0.2 rad/s or more");
  }
  const double share_up = static_cast<double>(up) / static_cast<double>(used);
  const double share_down = static_cast<double>(down) / static_cast<double>(used);
  if (share_up < kMinShareEachWay || share_down < kMinShareEachWay) {
    throw Error(j + ": Coulomb friction not excited: " + j + " moves faster than " +
                number_text(smoothing) + " rad/s in the positive direction on " +
                number_text(100.0 * share_up, 3) + " % and in the negative direction on " +
                number_text(100.0 * share_down, 3) +
                " % of the samples; record a motion that moves it both ways");
  }
}

JointFrictionFit fit_joint(const JointSeries& s, const std::vector<char>& use,
                           const CalibrationOptions& options, int joint) {
  const std::size_t N = s.dq.size();
  std::vector<double> ones(N, 1.0), z_viscous, z_offset, phi(N), z_coulomb, z_inertia;
  filter_regressor(s.dq, s.alpha, z_viscous, s.filter_weight);
  filter_regressor(ones, s.alpha, z_offset, s.filter_weight);
  const bool try_inertia = options.inertia_correction && !s.dt.empty();
  // δI is added to the momentum's q̇ (the velocity filter's, where one is configured); the
  // velocity's noise that the momentum passes (s.momentum_fast) is a nuisance column of its
  // fit: central differences of a noisy q̇ follow that noise, and δI would be fitted to cancel
  // it (−0.26 kg m² on the real Panda's joint 2, which needs none) where the estimator, without
  // the column, gains nothing.
  const std::vector<double>& inertia_dq = s.momentum_dq.empty() ? s.dq : s.momentum_dq;
  const std::vector<double>& z_noise = s.momentum_fast;
  if (try_inertia) filter_rate(inertia_dq, s.alpha, s.dt, z_inertia, s.filter_weight);
  std::vector<double> smoothings(kSmoothingGrid.begin(), kSmoothingGrid.end());
  if (options.sign == SmoothSign::kDahl)
    smoothings.assign(kPreslidingGrid.begin(), kPreslidingGrid.end());
  if (options.smoothing_velocity > 0) smoothings = {options.smoothing_velocity};
  std::vector<double> shifts{0.0};
  if (options.sign == SmoothSign::kSigmoid) shifts.assign(kShiftGrid.begin(), kShiftGrid.end());

  // The best friction alone; and for the inertia test, the best friction with the noise column
  // and the best with it and the inertia correction (each with its own Coulomb smoothing and
  // shift).
  JointFrictionFit best;
  double smoothing_with = 0.0, shift_with = 0.0;
  Solve<3> best_solve;
  Solve<4> best_solve_noise;
  Solve<5> best_solve_with;
  for (const double vs : smoothings) {
    for (const double shift : shifts) {
      coulomb_regressor(s, options.sign, vs, shift, phi);
      filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
      const Solve<3> sol =
          solve_friction<3>({&z_viscous, &z_coulomb, &z_offset}, s.r0, use, options.regularisation);
      if (sol.rss < best_solve.rss) {
        best_solve = sol;
        best.smoothing = vs;
        best.shift = shift;
      }
      if (!try_inertia) continue;
      const Solve<4> noise = solve_friction<4>({&z_viscous, &z_coulomb, &z_offset, &z_noise}, s.r0,
                                               use, options.regularisation);
      best_solve_noise = noise.rss < best_solve_noise.rss ? noise : best_solve_noise;
      const Solve<5> with =
          solve_friction<5>({&z_viscous, &z_coulomb, &z_offset, &z_noise, &z_inertia}, s.r0, use,
                            options.regularisation);
      if (with.rss < best_solve_with.rss) {
        best_solve_with = with;
        smoothing_with = vs;
        shift_with = shift;
      }
    }
  }
  const std::string j = joint_name(joint);
  if (options.sign != SmoothSign::kDahl && !s.q.empty())
    best.dahl = dahl_alternative(s, use, options.regularisation, best_solve.theta, best.smoothing,
                                 best.shift, options.sign, z_viscous, z_offset);
  if (best_solve.condition > kMaxCondition) {
    throw Error(j + ": viscous friction, Coulomb friction and offset cannot be told apart " +
                "(condition " + number_text(best_solve.condition, 3) + "); record a motion of " +
                j + " with slow and fast phases in both directions");
  }
  best.viscous = best_solve.theta[0];
  best.coulomb = best_solve.theta[1];
  best.offset = best_solve.theta[2];
  best.condition = best_solve.condition;
  // The inertia correction is kept where it explains a clear share of what friction and the
  // velocity's noise leave (a few per cent would be noise fitted), where the regression stays
  // well conditioned, and where it does so beyond a gravity error too: in a periodic motion q̈
  // follows q, and an error of g(q) (of the model's masses, or a payload on the last link) would
  // be taken for an inertia. The noise and gravity columns are nuisance regressors of these
  // tests only (the gravity test without the noise's: with it, the five gravity columns took
  // the real Panda's joint 4 error, which δI removes on the held-out part too).
  bool keep_inertia = try_inertia && best_solve_with.condition <= kMaxCondition &&
                      best_solve_with.rss <= (1.0 - kMinInertiaGain) * best_solve_noise.rss;
  if (keep_inertia && !s.payload_gravity[0].empty()) {
    std::array<std::vector<double>, 5> z_gravity;
    filter_regressor(s.gravity, s.alpha, z_gravity[0], s.filter_weight);
    for (std::size_t c = 0; c < 4; ++c)
      filter_regressor(s.payload_gravity[c], s.alpha, z_gravity[c + 1], s.filter_weight);
    coulomb_regressor(s, options.sign, best.smoothing, best.shift, phi);
    filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
    const Solve<8> g =
        solve_friction<8>({&z_viscous, &z_coulomb, &z_offset, &z_gravity[0], &z_gravity[1],
                           &z_gravity[2], &z_gravity[3], &z_gravity[4]},
                          s.r0, use, options.regularisation);
    const Solve<9> gi =
        solve_friction<9>({&z_viscous, &z_coulomb, &z_offset, &z_gravity[0], &z_gravity[1],
                           &z_gravity[2], &z_gravity[3], &z_gravity[4], &z_inertia},
                          s.r0, use, options.regularisation);
    keep_inertia = gi.rss <= (1.0 - kMinInertiaGain) * g.rss;
  }
  const double inertia = best_solve_with.theta[4];
  // One sine per joint: q̈ follows q, and an inertia cannot be told from a gravity error that
  // changes with q_i. Not applied; said, with what motion would tell them apart.
  double correlation = 0.0;
  if (keep_inertia && inertia_aliases_gravity(s, central_acceleration(s), use, correlation)) {
    keep_inertia = false;
    best.warnings.push_back(
        j + ": an inertia correction (" + number_text(inertia, 3) +
        " kg m^2 fitted) is not applied: in this motion its acceleration follows its position " +
        "(correlation " + number_text(correlation, 3) + ", as with one sine per joint), so it " +
        "cannot be told from a gravity error that changes with the joint's angle (a centre of " +
        "mass off); record a motion that moves " + j + " with several frequencies at once");
  }
  if (keep_inertia) {
    // The estimator has no noise column: friction refitted with δI held, on r⁰ + δI z_I, and δI
    // kept only where the residual the estimator will see is smaller than with friction alone
    // (δI q̇ also adds δI δq̇ of the velocity's noise).
    std::vector<double> held_r0 = s.r0;
    for (std::size_t k = 0; k < N; ++k) held_r0[k] += inertia * z_inertia[k];
    coulomb_regressor(s, options.sign, smoothing_with, shift_with, phi);
    filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
    const Solve<3> held = solve_friction<3>({&z_viscous, &z_coulomb, &z_offset}, held_r0, use,
                                            options.regularisation);
    if (held.rss < best_solve.rss) {
      best.viscous = held.theta[0];
      best.coulomb = held.theta[1];
      best.offset = held.theta[2];
      best.smoothing = smoothing_with;
      best.shift = shift_with;
      best.inertia = inertia;
      best.inertia_gain = 1.0 - held.rss / best_solve.rss;
      best.condition = best_solve_with.condition;
    }
  }
  // A sign fitted to rounding (an ideal simulated log) is not worth a warning.
  if (best_solve.count > 0.0 && std::sqrt(best_solve.rr / best_solve.count) >= kResolvableTorque) {
    if (best.viscous == 0.0) best.warnings.push_back(j + ": viscous friction fitted < 0, set to 0");
    if (best.coulomb == 0.0) best.warnings.push_back(j + ": Coulomb friction fitted < 0, set to 0");
  }
  // The residual with the chosen friction, over the whole log.
  coulomb_regressor(s, options.sign, best.smoothing, best.shift, phi);
  filter_regressor(phi, s.alpha, z_coulomb, s.filter_weight);
  best.residual.resize(N);
  for (std::size_t k = 0; k < N; ++k)
    best.residual[k] = s.r0[k] + best.viscous * z_viscous[k] + best.coulomb * z_coulomb[k] +
                       best.offset * z_offset[k];
  if (best.inertia != 0.0)
    for (std::size_t k = 0; k < N; ++k) best.residual[k] += best.inertia * z_inertia[k];
  return best;
}

}  // namespace extwrench::calibration_detail
