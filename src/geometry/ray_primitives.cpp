// Line / surface intersection for the primitive shapes (sphere, box, cylinder, capsule): hits
// and, on a miss, the nearest surface point.
#include <algorithm>
#include <array>
#include <cmath>

#include "ray_detail.hpp"

namespace extwrench::ray_detail {
namespace {

// A unit-direction component below this is treated as exactly zero (parallel to a box face or
// to the cylinder axis); only guards 0/0 and denormal overflow, no geometric approximation.
constexpr double kTinyComponent = 1e-300;

// Golden-section iterations for the convex line-to-solid distance: 0.618^64 ≈ 4e-14 of the
// bounding diameter in λ; the distance is smooth at a miss's minimum, so its error is ~λ error².
constexpr int kGoldenIterations = 64;

// ---- primitives (shape frame; o = point on the line, u = unit direction) ---------------------

void sphere_hits(double r, const Vector3& c, const Vector3& o, const Vector3& u, ShapeHit* out,
                 int& n) noexcept {
  // |o + λu − c|² = r²: from the foot of the perpendicular f (λ₀ = u·(c − o)), λ = λ₀ ± h with
  // h² = r² − |f − c|², which keeps its precision for lines far from the centre.
  const double l0 = u.dot(c - o);
  const Vector3 f = o + l0 * u;
  const double h2 = r * r - (f - c).squaredNorm();
  if (!(h2 >= 0.0)) return;
  const double h = std::sqrt(h2);
  for (const double l : {l0 - h, l0 + h}) {
    ShapeHit& hit = out[n++];
    hit.lambda = l;
    hit.point_G = o + l * u;
    hit.normal_G = (hit.point_G - c) / r;
  }
}

int box_hits(const Vector3& half, const Vector3& o, const Vector3& u, ShapeHit* out) noexcept {
  // Slabs: intersect the λ intervals where |o_i + λu_i| ≤ h_i; remember which face bounds them.
  double t_near = -kInf, t_far = kInf;
  int i_near = -1, i_far = -1;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(u[i]) < kTinyComponent) {
      if (std::abs(o[i]) > half[i]) return 0;  // parallel to the slab and outside it
      continue;
    }
    double t1 = (-half[i] - o[i]) / u[i];
    double t2 = (half[i] - o[i]) / u[i];
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_near) {
      t_near = t1;
      i_near = i;
    }
    if (t2 < t_far) {
      t_far = t2;
      i_far = i;
    }
  }
  if (i_near < 0 || i_far < 0 || !(t_near <= t_far)) return 0;
  // Entry through the face the direction points into, exit through the opposite one; the face
  // coordinate is set exactly.
  const double s_near = u[i_near] > 0.0 ? -1.0 : 1.0;
  const double s_far = u[i_far] > 0.0 ? 1.0 : -1.0;
  out[0].lambda = t_near;
  out[0].point_G = o + t_near * u;
  out[0].point_G[i_near] = s_near * half[i_near];
  out[0].normal_G = s_near * Vector3::Unit(i_near);
  out[1].lambda = t_far;
  out[1].point_G = o + t_far * u;
  out[1].point_G[i_far] = s_far * half[i_far];
  out[1].normal_G = s_far * Vector3::Unit(i_far);
  return 2;
}

/// λ interval where the line is inside the infinite cylinder x² + y² ≤ r². False if never.
/// A line along the axis (u_xy = 0) gives (−inf, inf) when inside.
bool lateral_interval(double r, const Vector3& o, const Vector3& u, double& t1,
                      double& t2) noexcept {
  const double rho_u = std::sqrt(u.x() * u.x() + u.y() * u.y());
  if (rho_u < kTinyComponent) {
    if (o.x() * o.x() + o.y() * o.y() > r * r) return false;
    t1 = -kInf;
    t2 = kInf;
    return true;
  }
  // In the xy plane, with the unit 2D direction e = u_xy/|u_xy|: foot point q, half chord h.
  const double ex = u.x() / rho_u, ey = u.y() / rho_u;
  const double s0 = -(o.x() * ex + o.y() * ey);
  const double qx = o.x() + s0 * ex, qy = o.y() + s0 * ey;
  const double h2 = r * r - (qx * qx + qy * qy);
  if (!(h2 >= 0.0)) return false;
  const double h = std::sqrt(h2);
  t1 = (s0 - h) / rho_u;
  t2 = (s0 + h) / rho_u;
  return true;
}

ShapeHit lateral_hit(double r, const Vector3& o, const Vector3& u, double t) noexcept {
  ShapeHit hit;
  hit.lambda = t;
  hit.point_G = o + t * u;
  hit.normal_G = Vector3(hit.point_G.x(), hit.point_G.y(), 0.0) / r;
  return hit;
}

int cylinder_hits(double r, double hl, const Vector3& o, const Vector3& u, ShapeHit* out) noexcept {
  double t_near = -kInf, t_far = kInf;
  if (!lateral_interval(r, o, u, t_near, t_far)) return 0;
  bool near_cap = false, far_cap = false;
  if (std::abs(u.z()) < kTinyComponent) {
    if (std::abs(o.z()) > hl) return 0;
  } else {
    double z1 = (-hl - o.z()) / u.z();
    double z2 = (hl - o.z()) / u.z();
    if (z1 > z2) std::swap(z1, z2);
    if (z1 > t_near) {
      t_near = z1;
      near_cap = true;
    }
    if (z2 < t_far) {
      t_far = z2;
      far_cap = true;
    }
  }
  if (!(t_near <= t_far) || !std::isfinite(t_near) || !std::isfinite(t_far)) return 0;
  const auto cap_hit = [&](double t, double sign) {
    ShapeHit hit;
    hit.lambda = t;
    hit.point_G = o + t * u;
    hit.point_G.z() = sign * hl;
    hit.normal_G = sign * Vector3::UnitZ();
    return hit;
  };
  out[0] = near_cap ? cap_hit(t_near, u.z() > 0.0 ? -1.0 : 1.0) : lateral_hit(r, o, u, t_near);
  out[1] = far_cap ? cap_hit(t_far, u.z() > 0.0 ? 1.0 : -1.0) : lateral_hit(r, o, u, t_far);
  return 2;
}

int capsule_hits(double r, double hl, const Vector3& o, const Vector3& u, ShapeHit* out) noexcept {
  // The capsule is the union of a finite cylinder and two balls, and convex, so its λ interval is
  // the union of theirs: entry = smallest entry, exit = largest exit. A cylinder end-cap point
  // lies inside a ball, whose own entry is smaller, so only lateral hits need be candidates.
  std::array<ShapeHit, 6> c;
  int n = 0;
  sphere_hits(r, Vector3(0.0, 0.0, hl), o, u, c.data(), n);
  sphere_hits(r, Vector3(0.0, 0.0, -hl), o, u, c.data(), n);
  double t1 = 0.0, t2 = 0.0;
  if (lateral_interval(r, o, u, t1, t2) && std::isfinite(t1)) {
    for (const double t : {t1, t2}) {
      const ShapeHit hit = lateral_hit(r, o, u, t);
      if (std::abs(hit.point_G.z()) <= hl) c[n++] = hit;
    }
  }
  if (n == 0) return 0;
  int i_min = 0, i_max = 0;
  for (int i = 1; i < n; ++i) {
    if (c[i].lambda < c[i_min].lambda) i_min = i;
    if (c[i].lambda > c[i_max].lambda) i_max = i;
  }
  out[0] = c[i_min];
  out[1] = c[i_max];
  return 2;
}

/// Nearest points between the line o + λu and the segment a + s(b − a), s ∈ [0, 1]: returns the
/// segment point; sets λ and the distance.
Vector3 segment_closest_to_line(const Vector3& a, const Vector3& b, const Vector3& o,
                                const Vector3& u, double& lambda, double& distance) noexcept {
  // Minimise |P⊥(a + s e − o)|² over s, P⊥ = I − u uᵀ (λ then follows as u·(q − o)).
  const Vector3 e = b - a;
  const Vector3 w = a - o;
  const Vector3 e_perp = e - e.dot(u) * u;
  const Vector3 w_perp = w - w.dot(u) * u;
  const double ee = e_perp.squaredNorm();
  double s = 0.0;
  if (ee > 1e-30 * e.squaredNorm()) s = std::clamp(-w_perp.dot(e_perp) / ee, 0.0, 1.0);
  const Vector3 q = a + s * e;
  lambda = u.dot(q - o);
  distance = (q - o - lambda * u).norm();
  return q;
}

/// Golden-section search of λ ↦ dist(p(λ), solid), convex for a convex solid; the minimiser
/// lies within the bounding sphere's shadow [λ_c − R, λ_c + R] (the optimal segment between the
/// line and the solid is perpendicular to the line).
template <class Project>
ShapeClosestPoint golden_closest(const Vector3& o, const Vector3& u, double bound,
                                 Project&& project) noexcept {
  const auto f = [&](double l) {  // squared distance: same minimiser, no square root
    const Vector3 p = o + l * u;
    return (p - project(p)).squaredNorm();
  };
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  const double lc = -o.dot(u);
  double a = lc - bound, b = lc + bound;
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < kGoldenIterations; ++i) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  ShapeClosestPoint cp;
  cp.lambda = 0.5 * (a + b);
  const Vector3 p = o + cp.lambda * u;
  cp.point_G = project(p);
  cp.distance = (p - cp.point_G).norm();
  return cp;
}

}  // namespace

int primitive_hits(const CollisionShape& shape, const Vector3& o, const Vector3& u,
                   ShapeHit* out) noexcept {
  int n = 0;
  switch (shape.type) {
    case ShapeType::kSphere:
      sphere_hits(shape.radius, Vector3::Zero(), o, u, out, n);
      break;
    case ShapeType::kBox:
      n = box_hits(0.5 * shape.size, o, u, out);
      break;
    case ShapeType::kCylinder:
      n = cylinder_hits(shape.radius, 0.5 * shape.length, o, u, out);
      break;
    case ShapeType::kCapsule:
      n = capsule_hits(shape.radius, 0.5 * shape.length, o, u, out);
      break;
    case ShapeType::kMesh:  // ray_mesh.cpp
      break;
  }
  return n;
}

ShapeClosestPoint primitive_closest_on_miss(const CollisionShape& shape, const Vector3& o,
                                            const Vector3& u) noexcept {
  ShapeClosestPoint cp;
  switch (shape.type) {
    case ShapeType::kSphere: {
      cp.lambda = -o.dot(u);
      const Vector3 f = o + cp.lambda * u;
      const double d = f.norm();
      cp.point_G =
          d > 0.0 ? Vector3(shape.radius / d * f) : Vector3(shape.radius * Vector3::UnitZ());
      cp.distance = std::max(d - shape.radius, 0.0);
      return cp;
    }
    case ShapeType::kCapsule: {
      const double hl = 0.5 * shape.length;
      double axis_distance = 0.0;
      const Vector3 q = segment_closest_to_line(Vector3(0.0, 0.0, -hl), Vector3(0.0, 0.0, hl), o, u,
                                                cp.lambda, axis_distance);
      const Vector3 to_line = o + cp.lambda * u - q;
      const double n = to_line.norm();
      cp.point_G = q + (n > 0.0 ? Vector3(shape.radius / n * to_line)
                                : Vector3(shape.radius * Vector3::UnitX()));
      cp.distance = std::max(axis_distance - shape.radius, 0.0);
      return cp;
    }
    case ShapeType::kBox: {
      const Vector3 half = 0.5 * shape.size;
      return golden_closest(o, u, half.norm(), [&](const Vector3& p) -> Vector3 {
        return p.cwiseMax(-half).cwiseMin(half);
      });
    }
    case ShapeType::kCylinder: {
      const double r = shape.radius, hl = 0.5 * shape.length;
      return golden_closest(o, u, std::hypot(r, hl), [&](const Vector3& p) -> Vector3 {
        const double rho2 = p.x() * p.x() + p.y() * p.y();
        const double k = rho2 > r * r ? r / std::sqrt(rho2) : 1.0;
        return {k * p.x(), k * p.y(), std::clamp(p.z(), -hl, hl)};
      });
    }
    case ShapeType::kMesh:  // ray_mesh.cpp
      break;
  }
  return cp;
}

}  // namespace extwrench::ray_detail
