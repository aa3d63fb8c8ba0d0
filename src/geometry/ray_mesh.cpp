// Line / triangle-mesh intersection: exact double-precision hits (brute force, or vetting a float
// ray caster's candidates) and, on a miss, the nearest surface point.
#include <array>
#include <cmath>

#include "ray_detail.hpp"

namespace extwrench::ray_detail {
namespace {

// Barycentric slack of the double-precision triangle test. Brute force: only rounding, so an
// edge crossing is not lost between two triangles. Candidates from a float ray caster: a hit
// within float error of an edge may be reported on the neighbour only; such "loose" hits are
// used only where no exact hit lies within kLooseWindow.
constexpr double kStrictSlack = 1e-12;
constexpr double kLooseSlack = 1e-5;
constexpr double kLooseWindow = 1e-6;  // [m]

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
  hit.point_G = o + hit.lambda * u;
  hit.normal_G = e1.cross(e2).normalized();
  return true;
}

// One query's state. The arrays are left uninitialised (only their first num_* entries are
// read): a query is ~2 000 instructions, zeroing them cost ~300.
struct MeshVisit {
  MeshVisit(const TriangleMesh& m, const Vector3& origin, const Vector3& direction,
            HitSink& s) noexcept
      : mesh(&m), o(origin), u(direction), sink(&s) {}
  const TriangleMesh* mesh;
  Vector3 o;
  Vector3 u;
  HitSink* sink;
  std::array<int, 16> loose;  // triangles of loose hits (refined again when kept)
  int num_loose = 0;
  std::array<double, 64> exact;  // λ of exact hits, to vet the loose ones
  int num_exact = 0;
};

// Refines a candidate in double: an exact hit goes to the sink (true), a loose one is kept aside.
bool crossing_candidate(void* user, int tri) noexcept {
  auto& v = *static_cast<MeshVisit*>(user);
  if (tri < 0 || tri >= v.mesh->triangles.cols()) return false;
  ShapeHit hit;
  if (line_triangle(*v.mesh, tri, v.o, v.u, kStrictSlack, hit)) {
    v.sink->add(hit);
    if (v.num_exact < static_cast<int>(v.exact.size())) v.exact[v.num_exact++] = hit.lambda;
    return true;
  }
  if (line_triangle(*v.mesh, tri, v.o, v.u, kLooseSlack, hit)) {
    if (v.num_loose < static_cast<int>(v.loose.size())) {
      v.loose[static_cast<std::size_t>(v.num_loose++)] = tri;
    } else {
      v.sink->add(hit);
    }
  }
  return false;
}

void visit_candidate(void* user, int tri) noexcept {
  static_cast<void>(crossing_candidate(user, tri));
}

// A loose hit is the float caster's pick of the wrong triangle at an edge: kept only if the
// right one was not reported.
void add_uncovered_loose_hits(const MeshVisit& v) noexcept {
  for (int i = 0; i < v.num_loose; ++i) {
    ShapeHit hit;  // the same refinement as when it was found
    if (!line_triangle(*v.mesh, v.loose[static_cast<std::size_t>(i)], v.o, v.u, kLooseSlack, hit))
      continue;
    bool covered = false;
    for (int j = 0; j < v.num_exact && !covered; ++j) {
      covered = std::abs(v.exact[static_cast<std::size_t>(j)] - hit.lambda) <= kLooseWindow;
    }
    if (!covered) v.sink->add(hit);
  }
}

/// Unit vectors completing u to an orthonormal basis.
void orthonormal_basis(const Vector3& u, Vector3& e1, Vector3& e2) noexcept {
  int k = 0;  // the axis least aligned with u
  u.cwiseAbs().minCoeff(&k);
  e1 = u.cross(Vector3::Unit(k)).normalized();
  e2 = u.cross(e1);
}

}  // namespace

void mesh_hits(const TriangleMesh& mesh, const Vector3& o, const Vector3& u,
               HitSink& sink) noexcept {
  if (mesh.ray_caster == nullptr) {
    ShapeHit hit;
    for (Eigen::Index t = 0; t < mesh.triangles.cols(); ++t) {
      if (line_triangle(mesh, static_cast<int>(t), o, u, kStrictSlack, hit)) sink.add(hit);
    }
    return;
  }
  MeshVisit v(mesh, o, u, sink);
  mesh.ray_caster->for_each_line_candidate(o, u, &visit_candidate, &v);
  add_uncovered_loose_hits(v);
}

void mesh_first_hits(const TriangleMesh& mesh, const Vector3& o, const Vector3& u, HitSink& sink,
                     double max_lambda) noexcept {
  if (mesh.ray_caster == nullptr) {
    mesh_hits(mesh, o, u, sink);
    return;
  }
  MeshVisit v(mesh, o, u, sink);
  mesh.ray_caster->for_each_first_crossing_candidate(o, u, max_lambda, &crossing_candidate, &v);
  add_uncovered_loose_hits(v);
}

/// Surface point of a mesh nearest to a line that misses it. The distance from the line to a
/// point x is |P⊥(x − o)|, so in the plane ⊥ u the line is the origin and each edge a segment:
/// the 3D line-to-edge distance is a 2D point-to-segment distance. A line missing a triangle is
/// nearest to it on an edge, hence the scan over edges (shared edges are seen twice).
ShapeClosestPoint mesh_closest_on_miss(const TriangleMesh& m, const Vector3& o,
                                       const Vector3& u) noexcept {
  ShapeClosestPoint cp;
  cp.distance = kInf;
  cp.point_G.setConstant(kNaN);
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
  cp.point_G = a + best_s * (b - a);
  cp.lambda = u.dot(cp.point_G - o);
  cp.distance = std::sqrt(best);
  return cp;
}

}  // namespace extwrench::ray_detail
