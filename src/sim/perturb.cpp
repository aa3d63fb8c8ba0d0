// Model errors drawn in a physically consistent parametrisation (docs/simulation.md "The
// perturbed model"): whatever the draw, every body keeps a positive mass and an inertia that a
// rigid body can have.
#include "extwrench/sim/perturb.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/sim/random.hpp"

namespace extwrench::sim {

namespace {

// The rotational inertia about the CoM, I = R diag(λ) Rᵀ, written with the principal second
// moments of the mass distribution J_k = ∫ x_k² dm = (λ₁ + λ₂ + λ₃)/2 − λ_k: every J_k >= 0 is
// exactly the positive semi-definiteness and the triangle inequality of λ, so scaling each J_k
// by (1 + u), |u| < 1, keeps both. The principal axes turn by an angle of at most `fraction`
// [rad] about a random axis. Each λ_k = J_i + J_j then moves by at most ±fraction of itself, and
// I by at most about fraction |I| in all.
Matrix3 perturb_rotational_inertia(const Matrix3& I, double fraction, Rng& rng) {
  const Eigen::SelfAdjointEigenSolver<Matrix3> eig(0.5 * (I + I.transpose()));
  const Vector3 l = eig.eigenvalues();
  const double half_trace = 0.5 * l.sum();
  Vector3 J = (Vector3::Constant(half_trace) - l).cwiseMax(0.0);  // rounding below 0: a plane
  for (int k = 0; k < 3; ++k) J[k] *= 1.0 + rng.uniform(-fraction, fraction);
  const Vector3 l_new(J[1] + J[2], J[0] + J[2], J[0] + J[1]);
  // A random unit axis (a normalised Gaussian draw is uniform on the sphere), a bounded angle.
  Vector3 axis(rng.normal(), rng.normal(), rng.normal());
  const double angle = rng.uniform(-fraction, fraction);
  const double norm = axis.norm();
  axis = norm > 0.0 ? Vector3(axis / norm) : Vector3(Vector3::UnitZ());
  const Matrix3 R = Eigen::AngleAxisd(angle, axis).toRotationMatrix() * eig.eigenvectors();
  const Matrix3 out = R * l_new.asDiagonal() * R.transpose();
  return 0.5 * (out + out.transpose());
}

}  // namespace

Model perturb_model(const Model& model, double fraction, std::uint64_t seed) {
  if (!(fraction >= 0.0 && fraction < 0.5)) {
    throw Error("perturb_model: fraction must be in [0, 0.5), got " + std::to_string(fraction));
  }
  Rng rng(seed);
  // Relative error within ±fraction of the nominal value (paper Sec. IV): x (1 + u).
  auto perturb = [&](double x) { return x * (1.0 + rng.uniform(-fraction, fraction)); };
  Model out = model;
  for (Body& body : out.bodies) {
    Inertia& in = body.inertia;
    in.mass = perturb(in.mass);  // stays positive (|u| < 1); zero stays zero
    for (int k = 0; k < 3; ++k) in.com[k] = perturb(in.com[k]);  // any CoM is physical
    in.inertia_com = perturb_rotational_inertia(in.inertia_com, fraction, rng);
  }
  // The rotors' reflected inertia, where there is one (no draw otherwise).
  for (std::size_t i = 1; i < out.joints.size(); ++i) {
    if (out.joints[i].armature != 0.0) out.joints[i].armature = perturb(out.joints[i].armature);
  }
  return out;
}

}  // namespace extwrench::sim
