// Damped least squares (Remark 6) for the Jacobian-transpose cases D and E of Table I
// (docs/estimator.md). With σ_1 ≥ … ≥ σ_min the singular values of J (R×n, R = 3 or 6) and
// ε = σ_1 / max_condition:
//   μ² = 0 if σ_min ≥ ε,   μ² = ε² − σ_min² otherwise,   x = (J Jᵀ + μ² I)⁻¹ J b,
// so the solution is exact up to the condition number max_condition, the damping grows smoothly
// as σ_min falls below ε, and the gain along the weakest direction stays ≤ 1/ε (bounded output).
// Observability is a rank test: σ_min ≤ rank_tolerance · σ_1 means the system cannot be solved
// at this configuration (rank_ok false, x NaN).
//
// Real time: header-only, noexcept, fixed-size storage (no allocation).
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "extwrench/core/types.hpp"

namespace extwrench {

struct SolverOptions {
  double max_condition = 1e3;  ///< κ above which damping starts (damped least squares)
  /// σ_min/σ_max at or below which the rank is deficient. σ comes from the eigenvalues of J Jᵀ,
  /// accurate to ~1e-8 σ_max, so the tolerance must stay well above that.
  double rank_tolerance = 1e-6;
};

struct DlsInfo {
  bool rank_ok = false;  ///< σ_min > rank_tolerance · σ_max
  bool damped = false;   ///< σ_min < σ_max / max_condition: damping active
  double condition = std::numeric_limits<double>::quiet_NaN();
  double damping = 0.0;  ///< μ² of the solve (uncertainty.hpp propagates through it)
};

/// Extreme eigenvectors of J Jᵀ at the last solve: where the next solve's power / inverse
/// iterations start. size = R (3 or 6) when valid, 0 to force the exact eigensolver.
struct SpectrumGuess {
  Vector6 v_min = Vector6::Zero();
  Vector6 v_max = Vector6::Zero();
  int size = 0;
};

/// A = L D Lᵀ in place (unit lower L below the diagonal, 1/D on it; the upper triangle is not
/// read): no square roots, and the solves multiply by the stored inverse pivots, which keeps
/// divisions off their dependency chains. False when A is not numerically positive definite.
/// Matrices of fixed capacity only (the fixed-size J Jᵀ, B(q) of the estimator): the pivots then
/// fit on the stack, and nothing is allocated.
template <typename Matrix>
[[nodiscard]] inline bool ldlt_in_place(Matrix& A) noexcept {
  static_assert(Matrix::MaxRowsAtCompileTime != Eigen::Dynamic, "needs a fixed capacity");
  const int n = static_cast<int>(A.rows());
  double d[Matrix::MaxRowsAtCompileTime];
  for (int j = 0; j < n; ++j) {
    double dj = A(j, j);
    for (int k = 0; k < j; ++k) dj -= A(j, k) * A(j, k) * d[k];
    if (!(dj > 0.0)) return false;
    d[j] = dj;
    const double inv = 1.0 / dj;
    A(j, j) = inv;
    for (int i = j + 1; i < n; ++i) {
      double sum = A(i, j);
      for (int k = 0; k < j; ++k) sum -= A(i, k) * A(j, k) * d[k];
      A(i, j) = sum * inv;
    }
  }
  return true;
}

/// X ← A⁻¹ X, every column as ldlt_solve does it (the same operations, so the same bits), the
/// columns side by side: their substitutions are independent and run as row operations (X
/// row-major with a fixed number of columns vectorises them) instead of one dependent chain
/// after another.
template <typename Matrix, typename Columns>
inline void ldlt_solve_columns(const Matrix& LD, Columns& X) noexcept {
  static_assert(Columns::ColsAtCompileTime != Eigen::Dynamic, "needs a fixed number of columns");
  // Each row is accumulated in registers and stored once: updated in place, every step would
  // store it and load it back (the compiler cannot tell X's rows apart).
  using Row = Eigen::Matrix<double, 1, Columns::ColsAtCompileTime>;
  const int n = static_cast<int>(LD.rows());
  for (int i = 1; i < n; ++i) {
    Row row = X.row(i);
    for (int k = 0; k < i; ++k) row -= LD(i, k) * X.row(k);
    X.row(i) = row;
  }
  for (int i = 0; i < n; ++i) X.row(i) *= LD(i, i);
  for (int i = n - 2; i >= 0; --i) {
    Row row = X.row(i);
    for (int k = i + 1; k < n; ++k) row -= LD(k, i) * X.row(k);
    X.row(i) = row;
  }
}

/// x ← A⁻¹ x with the factor of ldlt_in_place.
template <typename Matrix, typename Vector>
inline void ldlt_solve(const Matrix& LD, Vector& x) noexcept {
  const int n = static_cast<int>(LD.rows());
  for (int i = 1; i < n; ++i) {
    double xi = x[i];  // in a register, stored once (as in ldlt_solve_columns)
    for (int k = 0; k < i; ++k) xi -= LD(i, k) * x[k];
    x[i] = xi;
  }
  for (int i = 0; i < n; ++i) x[i] *= LD(i, i);
  for (int i = n - 2; i >= 0; --i) {
    double xi = x[i];
    for (int k = i + 1; k < n; ++k) xi -= LD(k, i) * x[k];
    x[i] = xi;
  }
}

namespace detail {
// Power / inverse iteration on J Jᵀ from the last solve's extreme eigenvectors: accepted once
// the relative residual ‖A v − ρ v‖/ρ is below kSpectrumTolerance for both ends, which bounds
// the eigenvalue error by ~tol² ρ²/gap (~1e-6 relative or better); else the exact path.
inline constexpr double kSpectrumTolerance = 1e-3;
inline constexpr int kSpectrumIterations = 4;

/// λ_min, λ_max of A (= J Jᵀ) into l_min, l_max; L is A's LDLᵀ factor when `factored`.
template <int R>
inline void extreme_eigenvalues(const Eigen::Matrix<double, R, R>& A,
                                const Eigen::Matrix<double, R, R>& L, bool factored,
                                SpectrumGuess& guess, double& l_min, double& l_max) noexcept {
  using VecR = Eigen::Matrix<double, R, 1>;
  bool estimated = false;
  if (factored && guess.size == R) {
    VecR v_max = guess.v_max.template head<R>();
    VecR v_min = guess.v_min.template head<R>();
    for (int it = 0; it < kSpectrumIterations && !estimated; ++it) {
      const VecR u = A * v_max;  // power step: λ_max ≈ ρ = vᵀ A v
      const double rho = v_max.dot(u);
      const double res_max = (u - rho * v_max).norm();
      v_max = u / u.norm();
      VecR y = v_min;  // inverse step: 1/λ_min ≈ μ = vᵀ A⁻¹ v
      ldlt_solve(L, y);
      const double mu = v_min.dot(y);
      const double res_min = (y - mu * v_min).norm();
      v_min = y / y.norm();
      l_max = rho;
      l_min = 1.0 / mu;
      estimated = res_max <= kSpectrumTolerance * rho && res_min <= kSpectrumTolerance * mu;
    }
    guess.v_max.template head<R>() = v_max;
    guess.v_min.template head<R>() = v_min;
  }
  if (!estimated) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, R, R>> eig(A);
    l_min = eig.eigenvalues()[0];
    l_max = eig.eigenvalues()[R - 1];
    guess.v_min.template head<R>() = eig.eigenvectors().col(0);
    guess.v_max.template head<R>() = eig.eigenvectors().col(R - 1);
    guess.size = R;
  }
}

/// A = J Jᵀ and y = J b over the first `cols` columns of J (R×n), as sums over the columns:
/// fixed-size R×R updates (the dynamic inner length of a product takes Eigen's generic path,
/// ~3× the instructions at these sizes).
template <int R, typename Derived, typename VectorB>
inline void normal_equations(const Eigen::MatrixBase<Derived>& J, int cols, const VectorB& b,
                             Eigen::Matrix<double, R, R>& A,
                             Eigen::Matrix<double, R, 1>& y) noexcept {
  A.setZero();
  y.setZero();
  for (int k = 0; k < cols; ++k) {
    const Eigen::Matrix<double, R, 1> j_k = J.col(k);
    A.noalias() += j_k * j_k.transpose();
    y += b[k] * j_k;
  }
}
}  // namespace detail

/// Solves Jᵀ x = b in the damped least-squares sense, J: R×n of which only the first `cols`
/// columns (the joints up to the contact link) can be non-zero. x = (J Jᵀ + μ² I)⁻¹ J b with
/// the damping law above, by an LDLᵀ factorisation (fixed size: no allocation). σ_min and
/// σ_max come from the extreme eigenvalues of A = J Jᵀ: J moves little between samples, so a few
/// power (λ_max) and inverse (λ_min, with the LDLᵀ factor) iterations from the previous
/// solve's eigenvectors (`guess`) usually suffice; otherwise (first sample, a change of link,
/// fast motion near a singularity) a full symmetric eigensolver gives them exactly and seeds the
/// next solve. The normal equations square κ: with κ ≤ 1e3 the relative error stays ~1e-10.
template <int R, typename Derived, typename VectorB>
inline DlsInfo damped_solve(const Eigen::MatrixBase<Derived>& J, int cols, const VectorB& b,
                            const SolverOptions& opt, Eigen::Matrix<double, R, 1>& x,
                            SpectrumGuess& guess) noexcept {
  using MatR = Eigen::Matrix<double, R, R>;
  MatR A;
  detail::normal_equations<R>(J, cols, b, A, x);
  MatR L = A;
  const bool factored = ldlt_in_place(L);
  double l_min = 0.0;
  double l_max = 0.0;
  detail::extreme_eigenvalues<R>(A, L, factored, guess, l_min, l_max);
  const double s_max = std::sqrt(std::max(l_max, 0.0));
  const double s_min = std::sqrt(std::max(l_min, 0.0));
  DlsInfo info;
  info.condition = s_min > 0.0 ? s_max / s_min : std::numeric_limits<double>::infinity();
  info.rank_ok = s_max > 0.0 && s_min > opt.rank_tolerance * s_max;
  const double eps = s_max / opt.max_condition;  // ε = σ_max / κ_max
  const double mu2 = s_min < eps ? eps * eps - s_min * s_min : 0.0;
  info.damped = mu2 > 0.0;
  info.damping = mu2;
  bool solved = false;
  if (info.rank_ok) {
    // rank_ok ⇒ σ_min > 0 ⇒ J Jᵀ + μ² I is positive definite (round-off checked).
    if (mu2 == 0.0 && factored) {
      solved = true;
    } else {
      L = A;
      L.diagonal().array() += mu2;
      solved = ldlt_in_place(L);
    }
    if (solved) ldlt_solve(L, x);
  }
  if (!solved) {
    info.rank_ok = false;
    x.setConstant(std::numeric_limits<double>::quiet_NaN());  // unobservable: not to be used
  }
  return info;
}

/// The observable part of a rank-deficient Jᵀ x = b (J: R×n, first `cols` columns): with
/// J Jᵀ = V Λ Vᵀ and the kept directions λ_i > (rank_tolerance · σ_max)², the least-squares
/// solution of smallest norm on them, x = Σ_kept v_i (v_iᵀ J b) / (λ_i + μ²), and the orthonormal
/// basis of the kept directions (the first `rank` columns of `basis`). μ² is damped_solve's law
/// on the kept directions, λ_r the smallest: μ² = ε² − λ_r when λ_r < ε², ε = σ_max /
/// max_condition, so the gain along the weakest kept direction stays ≤ 1/ε as in the full-rank
/// case (a short chain near its own singularity: undamped, a 1 N m residual read as 10 kN).
/// Components of x outside that subspace are not observable (zero here). Returns the rank (0:
/// nothing observable, x zero); `damping` gets μ² (0: undamped). Fixed-size eigensolver: no
/// allocation.
template <int R, typename Derived, typename VectorB>
inline int min_norm_solve(const Eigen::MatrixBase<Derived>& J, int cols, const VectorB& b,
                          const SolverOptions& opt, Eigen::Matrix<double, R, 1>& x,
                          Eigen::Matrix<double, R, R>& basis, double& damping) noexcept {
  using MatR = Eigen::Matrix<double, R, R>;
  using VecR = Eigen::Matrix<double, R, 1>;
  MatR A;
  VecR y;
  detail::normal_equations<R>(J, cols, b, A, y);
  const Eigen::SelfAdjointEigenSolver<MatR> eig(A);
  const VecR& lambda = eig.eigenvalues();  // increasing
  const double l_max = std::max(lambda[R - 1], 0.0);
  const double floor = opt.rank_tolerance * opt.rank_tolerance * l_max;
  x.setZero();
  basis.setZero();
  damping = 0.0;
  if (!(lambda[R - 1] > 0.0) || eig.info() != Eigen::Success) return 0;
  int first_kept = R - 1;
  while (first_kept > 0 && lambda[first_kept - 1] > floor) --first_kept;
  const double eps2 = l_max / (opt.max_condition * opt.max_condition);  // ε²
  if (lambda[first_kept] < eps2) damping = eps2 - lambda[first_kept];
  int rank = 0;
  for (int i = R - 1; i >= first_kept; --i) {
    const VecR v = eig.eigenvectors().col(i);
    x += v * (v.dot(y) / (lambda[i] + damping));
    basis.col(rank++) = v;
  }
  return rank;
}

}  // namespace extwrench
