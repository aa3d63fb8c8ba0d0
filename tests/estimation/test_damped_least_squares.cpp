// The damped least-squares solver of cases D and E (Remark 6, damped_least_squares.hpp) on its
// own, against Eigen's SVD: exact while κ ≤ max_condition, the damping law's solution (gain
// along the weakest direction ≤ 1/ε) beyond, NaN and rank_ok false when rank deficient; the
// observable part of a rank-deficient system by the same law on its kept directions.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "extwrench/estimation/damped_least_squares.hpp"
#include "support/test_robots.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

/// J = U diag(σ) Vᵀ (R×n) with random orthonormal U, V; zero beyond column `cols`.
template <int R>
Eigen::Matrix<double, R, Eigen::Dynamic> with_singular_values(
    const Eigen::Matrix<double, R, 1>& sigma, int n, int cols, SeededRng& rng) {
  Eigen::MatrixXd a(R, R), b(cols, cols);
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < R; ++j) a(i, j) = rng.uniform(-1, 1);
  for (int i = 0; i < cols; ++i)
    for (int j = 0; j < cols; ++j) b(i, j) = rng.uniform(-1, 1);
  const Eigen::MatrixXd U = Eigen::HouseholderQR<Eigen::MatrixXd>(a).householderQ();
  const Eigen::MatrixXd V = Eigen::HouseholderQR<Eigen::MatrixXd>(b).householderQ();
  Eigen::Matrix<double, R, Eigen::Dynamic> J = Eigen::Matrix<double, R, Eigen::Dynamic>::Zero(R, n);
  J.leftCols(cols) = U * sigma.asDiagonal() * V.leftCols(R).transpose();
  return J;
}

/// The damping law of the header written with the SVD of J: x = Σ_i σ_i/(σ_i² + μ²) u_i v_iᵀ b.
template <int R>
Eigen::Matrix<double, R, 1> svd_damped(const Eigen::Matrix<double, R, Eigen::Dynamic>& J, int cols,
                                       const VectorX& b, double max_condition) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J.leftCols(cols),
                                              Eigen::ComputeThinU | Eigen::ComputeThinV);
  const VectorX s = svd.singularValues();
  const double eps = s[0] / max_condition;
  const double s_min = s[R - 1];
  const double mu2 = s_min < eps ? eps * eps - s_min * s_min : 0.0;
  const VectorX vb = svd.matrixV().transpose() * b.head(cols);
  Eigen::Matrix<double, R, 1> x = Eigen::Matrix<double, R, 1>::Zero();
  for (int i = 0; i < R; ++i) x += svd.matrixU().col(i) * (s[i] / (s[i] * s[i] + mu2) * vb[i]);
  return x;
}

TEST(DampedLeastSquares, WellConditionedSolutionIsTheExactLeastSquaresOne) {
  SeededRng rng(21);
  const SolverOptions opt;
  for (int trial = 0; trial < 20; ++trial) {
    const int cols = 6 + trial % 2;  // square and over-determined Jᵀ x = b
    Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, 7);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 7; ++j) J(i, j) = j < cols ? rng.uniform(-1, 1) : 0.0;
    const VectorX b = rng.uniform_vector(7, -5, 5);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J.leftCols(cols).transpose(),
                                                Eigen::ComputeThinU | Eigen::ComputeThinV);
    const double kappa = svd.singularValues()[0] / svd.singularValues()[5];
    if (kappa > 100) continue;  // keep this test well inside the undamped range
    const Vector6 expected = svd.solve(b.head(cols));
    Vector6 x;
    SpectrumGuess guess;
    const DlsInfo info = damped_solve<6>(J, cols, b, opt, x, guess);
    EXPECT_TRUE(info.rank_ok);
    EXPECT_FALSE(info.damped);
    EXPECT_NEAR(info.condition, kappa, 1e-8 * kappa);
    EXPECT_LT((x - expected).norm(), 1e-10 * (1 + expected.norm())) << "trial " << trial;
    // A second solve from the first one's eigenvectors (the warm path) gives the same answer.
    Vector6 x2;
    const DlsInfo again = damped_solve<6>(J, cols, b, opt, x2, guess);
    EXPECT_TRUE(again.rank_ok);
    EXPECT_NEAR(again.condition, kappa, 1e-5 * kappa);
    EXPECT_LT((x2 - expected).norm(), 1e-10 * (1 + expected.norm()));
  }
}

TEST(DampedLeastSquares, IllConditionedSolutionFollowsTheDampingLawWithBoundedGain) {
  SeededRng rng(8);
  SolverOptions opt;
  opt.max_condition = 1e3;
  for (const double s_min : {5e-4, 1e-4, 1e-5}) {
    const Vector3 sigma(2.0, 0.7, s_min);  // κ = 2/σ_min > max_condition: damped
    const auto J = with_singular_values<3>(sigma, 7, 5, rng);
    const VectorX b = rng.uniform_vector(7, -3, 3);
    Vector3 x;
    SpectrumGuess guess;
    const DlsInfo info = damped_solve<3>(J, 5, b, opt, x, guess);
    EXPECT_TRUE(info.rank_ok);
    EXPECT_TRUE(info.damped);
    EXPECT_NEAR(info.condition, 2.0 / s_min, 1e-4 * 2.0 / s_min);
    const Vector3 expected = svd_damped<3>(J, 5, b, opt.max_condition);
    EXPECT_LT((x - expected).norm(), 1e-6 * expected.norm()) << "σ_min = " << s_min;
    // Bounded output: ‖x‖ ≤ ‖b‖ / ε with ε = σ_max / max_condition.
    EXPECT_LE(x.norm(), b.head(5).norm() * opt.max_condition / 2.0 * (1 + 1e-12));
  }
}

TEST(DampedLeastSquares, RankDeficientSystemIsReportedAndGivesNaN) {
  SeededRng rng(3);
  const Vector3 sigma(1.0, 0.5, 0.0);
  const auto J = with_singular_values<3>(sigma, 7, 4, rng);
  const VectorX b = rng.uniform_vector(7, -1, 1);
  Vector3 x;
  SpectrumGuess guess;
  const DlsInfo info = damped_solve<3>(J, 4, b, SolverOptions{}, x, guess);
  EXPECT_FALSE(info.rank_ok);
  EXPECT_TRUE(x.array().isNaN().all());
}

// The observable part (min_norm_solve) of a rank-deficient J (σ₃ = 0): the SVD's least-squares
// solution on the kept directions, exact while they are well conditioned and damped by the same
// law beyond (μ² = ε² − σ₂², gain ≤ 1/ε); before, it was undamped (gain 1/σ₂: 2e5 here).
TEST(DampedLeastSquares, ObservablePartFollowsTheDampingLawOnTheKeptDirections) {
  SeededRng rng(13);
  SolverOptions opt;
  opt.max_condition = 1e3;
  for (const double s_2 : {0.4, 5e-4, 1e-5}) {
    const Vector3 sigma(2.0, s_2, 0.0);
    const auto J = with_singular_values<3>(sigma, 7, 4, rng);
    const VectorX b = rng.uniform_vector(7, -3, 3);
    Vector3 x;
    Matrix3 basis;
    double damping = -1.0;
    const int rank = min_norm_solve<3>(J, 4, b, opt, x, basis, damping);
    ASSERT_EQ(rank, 2) << "σ_2 = " << s_2;
    // The SVD's: Σ_{i ≤ 2} u_i σ_i/(σ_i² + μ²) v_iᵀ b.
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J.leftCols(4),
                                                Eigen::ComputeThinU | Eigen::ComputeThinV);
    const VectorX s = svd.singularValues();
    const double eps = s[0] / opt.max_condition;
    const double mu2 = s[1] < eps ? eps * eps - s[1] * s[1] : 0.0;
    const VectorX vb = svd.matrixV().transpose() * b.head(4);
    Vector3 expected = Vector3::Zero();
    for (int i = 0; i < 2; ++i)
      expected += svd.matrixU().col(i) * (s[i] / (s[i] * s[i] + mu2) * vb[i]);
    EXPECT_NEAR(damping, mu2, 1e-9 * eps * eps) << "σ_2 = " << s_2;
    EXPECT_EQ(damping > 0.0, s_2 < 2.0 / opt.max_condition);
    EXPECT_LT((x - expected).norm(), 1e-6 * expected.norm()) << "σ_2 = " << s_2;
    EXPECT_LE(x.norm(), b.head(4).norm() * opt.max_condition / 2.0 * (1 + 1e-12));
    // The basis spans the kept directions u_1, u_2: orthonormal, and normal to u_3.
    const Eigen::Matrix<double, 3, 2> kept = basis.leftCols<2>();
    const Vector3 u_3 = svd.matrixU().col(2);
    EXPECT_LT((kept.transpose() * kept - Eigen::Matrix2d::Identity()).norm(), 1e-12);
    // (An eigenvector of J Jᵀ is accurate to ~ε_machine λ_max / gap: the normal equations.)
    const double gap = s_2 * s_2 / (sigma[0] * sigma[0]);
    EXPECT_LT((kept.transpose() * u_3).norm(), 4 * std::numeric_limits<double>::epsilon() / gap);
  }
}

TEST(DampedLeastSquares, LdltInPlaceSolvesLikeEigensLdlt) {
  SeededRng rng(5);
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 12>;
  for (int n : {1, 3, 7, 12}) {
    Eigen::MatrixXd a(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) a(i, j) = rng.uniform(-1, 1);
    const Eigen::MatrixXd A = a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
    const VectorX b = rng.uniform_vector(n, -2, 2);
    Mat LD = A;
    ASSERT_TRUE(ldlt_in_place(LD));
    VectorX x = b;
    ldlt_solve(LD, x);
    const VectorX expected = A.ldlt().solve(b);
    EXPECT_LT((x - expected).norm(), 1e-9 * (1 + expected.norm())) << "n = " << n;
  }
  Mat indefinite = Mat::Identity(3, 3);
  indefinite(1, 1) = -1.0;
  EXPECT_FALSE(ldlt_in_place(indefinite));
}

}  // namespace
}  // namespace extwrench
