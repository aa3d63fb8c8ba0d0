// Line / surface intersection for collision shapes (SPEC §4 C, eq. 21). Everything is
// allocation-free: hits go to fixed-size stack buffers, meshes are visited through callbacks.
#include "extwrench/geometry/ray.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace extwrench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A unit-direction component below this is treated as exactly zero (parallel to a box face or
// to the cylinder axis); only guards 0/0 and denormal overflow, no geometric approximation.
constexpr double kTinyComponent = 1e-300;

// Hits of one shape closer than this along the line are one hit (an edge shared by two mesh
// triangles is found twice). Far below any physical contact resolution.
constexpr double kSameHitLambda = 1e-10;  // [m]

// Barycentric slack of the double-precision triangle test. Brute force: only rounding, so an
// edge crossing is not lost between two triangles. Candidates from a float ray caster: a hit
// within float error of an edge may be reported on the neighbour only; such "loose" hits are
// used only where no exact hit lies within kLooseWindow.
constexpr double kStrictSlack = 1e-12;
constexpr double kLooseSlack = 1e-5;
constexpr double kLooseWindow = 1e-6;  // [m]

// Golden-section iterations for the convex line-to-solid distance: 0.618^64 ≈ 4e-14 of the
// bounding diameter in λ; the distance is smooth at a miss's minimum, so its error is ~λ error².
constexpr int kGoldenIterations = 64;

// Hits kept per shape by intersect_line_with_body; extreme hits are tracked beyond it.
constexpr int kMaxHitsPerShape = 32;

/// Collects one shape's hits sorted by λ in a caller buffer, merges coincident ones, and keeps
/// the extreme (smallest and largest λ) hits even when the buffer overflows.
class HitSink {
 public:
  explicit HitSink(std::span<ShapeHit> buffer) noexcept : buffer_(buffer) {}

  void add(const ShapeHit& h) noexcept {
    if (!std::isfinite(h.lambda)) return;
    if (distinct_ == 0 || h.lambda < first_.lambda) first_ = h;
    if (distinct_ == 0 || h.lambda > last_.lambda) last_ = h;
    // Sorted insertion; a hit within kSameHitLambda of a stored one is the same hit.
    int pos = 0;
    while (pos < size_ && buffer_[pos].lambda < h.lambda) ++pos;
    if ((pos < size_ && buffer_[pos].lambda - h.lambda <= kSameHitLambda) ||
        (pos > 0 && h.lambda - buffer_[pos - 1].lambda <= kSameHitLambda)) {
      return;
    }
    ++distinct_;
    const int capacity = static_cast<int>(buffer_.size());
    if (pos >= capacity) return;  // beyond the buffer: only counted (and tracked as extreme)
    const int last = std::min(size_, capacity - 1);
    for (int i = last; i > pos; --i) buffer_[i] = buffer_[i - 1];
    buffer_[pos] = h;
    size_ = std::min(size_ + 1, capacity);
  }

  [[nodiscard]] int size() const noexcept { return size_; }
  [[nodiscard]] int distinct() const noexcept { return distinct_; }
  [[nodiscard]] const ShapeHit& first() const noexcept { return first_; }
  [[nodiscard]] const ShapeHit& last() const noexcept { return last_; }

 private:
  std::span<ShapeHit> buffer_;
  int size_ = 0;
  int distinct_ = 0;
  ShapeHit first_;
  ShapeHit last_;
};

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
    hit.point = o + l * u;
    hit.normal = (hit.point - c) / r;
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
  out[0].point = o + t_near * u;
  out[0].point[i_near] = s_near * half[i_near];
  out[0].normal = s_near * Vector3::Unit(i_near);
  out[1].lambda = t_far;
  out[1].point = o + t_far * u;
  out[1].point[i_far] = s_far * half[i_far];
  out[1].normal = s_far * Vector3::Unit(i_far);
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
  hit.point = o + t * u;
  hit.normal = Vector3(hit.point.x(), hit.point.y(), 0.0) / r;
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
    hit.point = o + t * u;
    hit.point.z() = sign * hl;
    hit.normal = sign * Vector3::UnitZ();
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
      if (std::abs(hit.point.z()) <= hl) c[n++] = hit;
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

// ---- meshes --------------------------------------------------------------------------------

/// Exact line / triangle intersection in double (Möller–Trumbore on the infinite line).
/// Returns false if the line is parallel to the triangle's plane or passes outside it by more
/// than `slack` in barycentric coordinates.
bool line_triangle(const TriangleMesh& mesh, int tri, const Vector3& o, const Vector3& u,
                   double slack, ShapeHit& hit) noexcept {
  const Vector3 v0 = mesh.vertices.col(mesh.triangles(0, tri));
  const Vector3 e1 = mesh.vertices.col(mesh.triangles(1, tri)) - v0;
  const Vector3 e2 = mesh.vertices.col(mesh.triangles(2, tri)) - v0;
  const Vector3 pv = u.cross(e2);
  const double det = e1.dot(pv);  // = u·(e1 × e2)
  // The line lies in the plane (relative to the triangle's size), or the triangle is degenerate.
  if (!(det * det > 1e-28 * e1.squaredNorm() * e2.squaredNorm())) return false;
  const double inv_det = 1.0 / det;
  const Vector3 tv = o - v0;
  const double b1 = tv.dot(pv) * inv_det;
  if (b1 < -slack || b1 > 1.0 + slack) return false;
  const Vector3 qv = tv.cross(e1);
  const double b2 = u.dot(qv) * inv_det;
  if (b2 < -slack || b1 + b2 > 1.0 + slack) return false;
  hit.lambda = e2.dot(qv) * inv_det;
  hit.point = o + hit.lambda * u;
  hit.normal = e1.cross(e2).normalized();
  return true;
}

struct MeshVisit {
  const TriangleMesh* mesh;
  Vector3 o;
  Vector3 u;
  HitSink* sink;
  std::array<ShapeHit, 16> loose;
  int num_loose = 0;
  std::array<double, 64> exact;  // λ of exact hits, to vet the loose ones
  int num_exact = 0;
};

void visit_candidate(void* user, int tri) noexcept {
  auto& v = *static_cast<MeshVisit*>(user);
  if (tri < 0 || tri >= v.mesh->triangles.cols()) return;
  ShapeHit hit;
  if (line_triangle(*v.mesh, tri, v.o, v.u, kStrictSlack, hit)) {
    v.sink->add(hit);
    if (v.num_exact < static_cast<int>(v.exact.size())) v.exact[v.num_exact++] = hit.lambda;
  } else if (line_triangle(*v.mesh, tri, v.o, v.u, kLooseSlack, hit)) {
    if (v.num_loose < static_cast<int>(v.loose.size())) {
      v.loose[v.num_loose++] = hit;
    } else {
      v.sink->add(hit);
    }
  }
}

void mesh_hits(const TriangleMesh& mesh, const Vector3& o, const Vector3& u,
               HitSink& sink) noexcept {
  if (mesh.ray_caster == nullptr) {
    ShapeHit hit;
    for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
      if (line_triangle(mesh, static_cast<int>(t), o, u, kStrictSlack, hit)) sink.add(hit);
    }
    return;
  }
  MeshVisit v{&mesh, o, u, &sink, {}, 0, {}, 0};
  mesh.ray_caster->for_each_line_candidate(o, u, &visit_candidate, &v);
  // A loose hit is the float caster's pick of the wrong triangle at an edge: keep it only if the
  // right one was not reported.
  for (int i = 0; i < v.num_loose; ++i) {
    bool covered = false;
    for (int j = 0; j < v.num_exact && !covered; ++j) {
      covered = std::abs(v.exact[j] - v.loose[i].lambda) <= kLooseWindow;
    }
    if (!covered) sink.add(v.loose[i]);
  }
}

void collect_hits(const CollisionShape& shape, const Vector3& o, const Vector3& u,
                  HitSink& sink) noexcept {
  std::array<ShapeHit, 4> h;
  int n = 0;
  switch (shape.type) {
    case ShapeType::kSphere:
      sphere_hits(shape.radius, Vector3::Zero(), o, u, h.data(), n);
      break;
    case ShapeType::kBox:
      n = box_hits(0.5 * shape.size, o, u, h.data());
      break;
    case ShapeType::kCylinder:
      n = cylinder_hits(shape.radius, 0.5 * shape.length, o, u, h.data());
      break;
    case ShapeType::kCapsule:
      n = capsule_hits(shape.radius, 0.5 * shape.length, o, u, h.data());
      break;
    case ShapeType::kMesh:
      if (shape.mesh != nullptr) mesh_hits(*shape.mesh, o, u, sink);
      break;
  }
  for (int i = 0; i < n; ++i) sink.add(h[i]);
}

// ---- closest points on a miss ----------------------------------------------------------------

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

/// Unit vectors completing u to an orthonormal basis.
void orthonormal_basis(const Vector3& u, Vector3& e1, Vector3& e2) noexcept {
  int k = 0;  // the axis least aligned with u
  u.cwiseAbs().minCoeff(&k);
  e1 = u.cross(Vector3::Unit(k)).normalized();
  e2 = u.cross(e1);
}

/// Surface point of a mesh nearest to a line that misses it. The distance from the line to a
/// point x is |P⊥(x − o)|, so in the plane ⊥ u the line is the origin and each edge a segment:
/// the 3D line-to-edge distance is a 2D point-to-segment distance. A line missing a triangle is
/// nearest to it on an edge, hence the scan over edges (shared edges are seen twice).
ShapeClosestPoint mesh_closest_on_miss(const TriangleMesh& m, const Vector3& o,
                                       const Vector3& u) noexcept {
  ShapeClosestPoint cp;
  cp.distance = kInf;
  cp.point.setConstant(kNaN);
  cp.lambda = kNaN;
  Vector3 e1, e2;
  orthonormal_basis(u, e1, e2);
  double best = kInf;
  Eigen::Index best_t = -1;
  int best_k = 0;
  double best_s = 0.0;
  for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Vector3 a = m.vertices.col(m.triangles(k, t)) - o;
      const Vector3 b = m.vertices.col(m.triangles((k + 1) % 3, t)) - o;
      const double ax = e1.dot(a), ay = e2.dot(a);
      const double dx = e1.dot(b) - ax, dy = e2.dot(b) - ay;
      const double dd = dx * dx + dy * dy;
      double sk = 0.0;
      if (dd > 0.0) sk = std::clamp(-(ax * dx + ay * dy) / dd, 0.0, 1.0);
      const double px = ax + sk * dx, py = ay + sk * dy;
      const double d2 = px * px + py * py;
      if (d2 < best) {
        best = d2;
        best_t = t;
        best_k = k;
        best_s = sk;
      }
    }
  }
  if (best_t < 0) return cp;
  const Vector3 a = m.vertices.col(m.triangles(best_k, best_t));
  const Vector3 b = m.vertices.col(m.triangles((best_k + 1) % 3, best_t));
  cp.point = a + best_s * (b - a);
  cp.lambda = u.dot(cp.point - o);
  cp.distance = std::sqrt(best);
  return cp;
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
  cp.point = project(p);
  cp.distance = (p - cp.point).norm();
  return cp;
}

ShapeClosestPoint closest_on_miss(const CollisionShape& shape, const Vector3& o,
                                  const Vector3& u) noexcept {
  ShapeClosestPoint cp;
  switch (shape.type) {
    case ShapeType::kSphere: {
      cp.lambda = -o.dot(u);
      const Vector3 f = o + cp.lambda * u;
      const double d = f.norm();
      cp.point = d > 0.0 ? Vector3(shape.radius / d * f) : Vector3(shape.radius * Vector3::UnitZ());
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
      cp.point = q + (n > 0.0 ? Vector3(shape.radius / n * to_line)
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
    case ShapeType::kMesh: {
      if (shape.mesh == nullptr) {
        cp.distance = kInf;
        cp.point.setConstant(kNaN);
        cp.lambda = kNaN;
        return cp;
      }
      return mesh_closest_on_miss(*shape.mesh, o, u);
    }
  }
  return cp;
}

}  // namespace

int intersect_line_with_shape(const CollisionShape& shape, const Vector3& origin_S,
                              const Vector3& direction_S, std::span<ShapeHit> hits) noexcept {
  HitSink sink(hits);
  collect_hits(shape, origin_S, direction_S, sink);
  return sink.size();
}

ShapeClosestPoint closest_point_to_line(const CollisionShape& shape, const Vector3& origin_S,
                                        const Vector3& direction_S) noexcept {
  std::array<ShapeHit, 1> first;
  HitSink sink(first);
  collect_hits(shape, origin_S, direction_S, sink);
  if (sink.distinct() > 0) {
    ShapeClosestPoint cp;
    cp.point = sink.first().point;
    cp.lambda = sink.first().lambda;
    cp.distance = 0.0;
    return cp;
  }
  return closest_on_miss(shape, origin_S, direction_S);
}

SurfacePointResult intersect_line_with_body(const GeometryModel& geometry, int body,
                                            const Pose& X_WB, const Vector3& point_on_line_W,
                                            const Vector3& direction_W) noexcept {
  SurfacePointResult result;
  const LineHit none{kNaN, Vector3::Constant(kNaN), Vector3::Constant(kNaN), -1};
  result.entry = none;
  result.exit = none;
  result.closest_point_W.setConstant(kNaN);
  result.closest_lambda = kNaN;
  result.distance = kNaN;

  const double norm = direction_W.norm();
  if (!(norm > 0.0) || !std::isfinite(norm) || !point_on_line_W.allFinite() ||
      !X_WB.rotation.allFinite() || !X_WB.translation.allFinite()) {
    return result;
  }
  result.distance = kInf;
  if (body < 0 || body >= static_cast<int>(geometry.body_shapes.size())) return result;
  // (21) p(λ) = p̂ + λ u, u = F̂/‖F̂‖
  const Vector3 u_W = direction_W / norm;
  const int num_shapes = static_cast<int>(geometry.shapes.size());

  const auto to_shape = [&](const CollisionShape& shape, Pose& X_WS, Vector3& o_S, Vector3& u_S) {
    X_WS = X_WB * shape.placement;
    o_S.noalias() = X_WS.rotation.transpose() * (point_on_line_W - X_WS.translation);
    u_S.noalias() = X_WS.rotation.transpose() * u_W;
  };

  std::array<ShapeHit, kMaxHitsPerShape> buffer;
  for (const int s : geometry.body_shapes[static_cast<std::size_t>(body)]) {
    if (s < 0 || s >= num_shapes) continue;
    const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
    Pose X_WS;
    Vector3 o_S, u_S;
    to_shape(shape, X_WS, o_S, u_S);
    HitSink sink(buffer);
    collect_hits(shape, o_S, u_S, sink);
    if (sink.distinct() == 0) continue;
    result.num_hits += sink.distinct();
    const bool is_mesh = shape.type == ShapeType::kMesh;
    const auto to_world = [&](const ShapeHit& h, double orient) {
      LineHit w{h.lambda, X_WS.act(h.point), X_WS.rotation * h.normal, s};
      // Mesh winding may be inward: the entry faces −u, the exit +u on a closed surface.
      if (is_mesh && orient * w.normal_W.dot(u_W) < 0.0) w.normal_W = -w.normal_W;
      return w;
    };
    if (!result.hit || sink.first().lambda < result.entry.lambda)
      result.entry = to_world(sink.first(), -1.0);
    if (!result.hit || sink.last().lambda > result.exit.lambda)
      result.exit = to_world(sink.last(), 1.0);
    result.hit = true;
  }

  if (result.hit) {
    result.closest_point_W = result.entry.point_W;
    result.closest_lambda = result.entry.lambda;
    result.distance = 0.0;
    result.shape = result.entry.shape;
    return result;
  }
  for (const int s : geometry.body_shapes[static_cast<std::size_t>(body)]) {
    if (s < 0 || s >= num_shapes) continue;
    const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
    Pose X_WS;
    Vector3 o_S, u_S;
    to_shape(shape, X_WS, o_S, u_S);
    const ShapeClosestPoint cp = closest_on_miss(shape, o_S, u_S);
    if (cp.distance < result.distance) {
      result.distance = cp.distance;
      result.closest_point_W = X_WS.act(cp.point);
      result.closest_lambda = cp.lambda;
      result.shape = s;
    }
  }
  return result;
}

}  // namespace extwrench
