// Line / surface intersection for collision shapes (the line of action (21), docs/estimator.md).
// Everything is allocation-free: hits go to fixed-size stack buffers, meshes are visited through
// callbacks. This file: the shape and body entry points; primitives in ray_primitives.cpp, meshes
// in ray_mesh.cpp.
#include "extwrench/geometry/ray.hpp"

#include <array>
#include <cmath>

#include "ray_detail.hpp"

namespace extwrench {
namespace {

using namespace ray_detail;

// Hits kept per shape by intersect_line_with_body; extreme hits are tracked beyond it.
constexpr int kMaxHitsPerShape = 32;

// Every hit; with `first_only`, those that give the first hit at λ ≤ max_lambda (meshes: a
// first-crossing search).
void collect_hits(const CollisionShape& shape, const Vector3& o, const Vector3& u, HitSink& sink,
                  bool first_only = false, double max_lambda = kInf) noexcept {
  if (shape.type == ShapeType::kMesh) {
    if (shape.mesh == nullptr) return;
    if (first_only) {
      mesh_first_hits(*shape.mesh, o, u, sink, max_lambda);
    } else {
      mesh_hits(*shape.mesh, o, u, sink);
    }
    return;
  }
  std::array<ShapeHit, 4> h;
  const int n = primitive_hits(shape, o, u, h.data());
  for (int i = 0; i < n; ++i) sink.add(h[i]);
}

ShapeClosestPoint closest_on_miss(const CollisionShape& shape, const Vector3& o,
                                  const Vector3& u) noexcept {
  if (shape.type != ShapeType::kMesh) return primitive_closest_on_miss(shape, o, u);
  if (shape.mesh == nullptr) {
    ShapeClosestPoint cp;
    cp.distance = kInf;
    cp.point_G.setConstant(kNaN);
    cp.lambda = kNaN;
    return cp;
  }
  return mesh_closest_on_miss(*shape.mesh, o, u);
}

// Calls visit(s, shape, X_WG, o_G, u_G) for every valid shape s of `body` (an index the caller
// checked): its pose X_WG = X_WB · placement and the line (point_W, unit u_W) in its frame G.
template <typename Visit>
void for_each_posed_shape(const GeometryModel& geometry, int body, const Pose& X_WB,
                          const Vector3& point_W, const Vector3& u_W, Visit&& visit) noexcept {
  const int num_shapes = static_cast<int>(geometry.shapes.size());
  for (const int s : geometry.body_shapes[static_cast<std::size_t>(body)]) {
    if (s < 0 || s >= num_shapes) continue;
    const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
    const Pose X_WG = X_WB * shape.placement;
    const Vector3 o_G = X_WG.rotation.transpose() * (point_W - X_WG.translation);
    const Vector3 u_G = X_WG.rotation.transpose() * u_W;
    visit(s, shape, X_WG, o_G, u_G);
  }
}

// A hit of shape s in W. Mesh winding may be inward: the entry faces −u (orient −1), the exit
// +u (orient +1) on a closed surface.
LineHit hit_in_world(const ShapeHit& h, const Pose& X_WG, const Vector3& u_W, bool is_mesh,
                     double orient, int s) noexcept {
  LineHit w{h.lambda, X_WG.act(h.point_G), X_WG.rotation * h.normal_G, s};
  if (is_mesh && orient * w.normal_W.dot(u_W) < 0.0) w.normal_W = -w.normal_W;
  return w;
}

// What both body queries check: a usable line and a posed body. Out: u_W, the unit direction.
bool usable_line(const Pose& X_WB, const Vector3& point_W, const Vector3& direction_W,
                 Vector3& u_W) noexcept {
  const double norm = direction_W.norm();
  if (!(norm > 0.0) || !std::isfinite(norm) || !point_W.allFinite() || !X_WB.rotation.allFinite() ||
      !X_WB.translation.allFinite()) {
    return false;
  }
  u_W = direction_W / norm;  // (21) p(λ) = p̂ + λ u, u = F̂/‖F̂‖
  return true;
}

}  // namespace

int intersect_line_with_shape(const CollisionShape& shape, const Vector3& origin_G,
                              const Vector3& direction_G, std::span<ShapeHit> hits) noexcept {
  HitSink sink(hits);
  collect_hits(shape, origin_G, direction_G, sink);
  return sink.size();
}

ShapeClosestPoint closest_point_to_line(const CollisionShape& shape, const Vector3& origin_G,
                                        const Vector3& direction_G) noexcept {
  std::array<ShapeHit, 1> first;
  HitSink sink(first);
  collect_hits(shape, origin_G, direction_G, sink);
  if (sink.distinct() > 0) {
    ShapeClosestPoint cp;
    cp.point_G = sink.first().point_G;
    cp.lambda = sink.first().lambda;
    cp.distance = 0.0;
    return cp;
  }
  return closest_on_miss(shape, origin_G, direction_G);
}

SurfacePointResult intersect_line_with_body(const GeometryModel& geometry, int body,
                                            const Pose& X_WB, const Vector3& point_on_line_W,
                                            const Vector3& direction_W, OnMiss on_miss) noexcept {
  SurfacePointResult result;
  const LineHit none{kNaN, Vector3::Constant(kNaN), Vector3::Constant(kNaN), -1};
  result.entry = none;
  result.exit = none;
  result.closest_point_W.setConstant(kNaN);
  result.closest_lambda = kNaN;
  result.distance = kNaN;

  Vector3 u_W;
  if (!usable_line(X_WB, point_on_line_W, direction_W, u_W)) return result;
  result.distance = kInf;
  if (body < 0 || body >= static_cast<int>(geometry.body_shapes.size())) return result;

  std::array<ShapeHit, kMaxHitsPerShape> buffer;
  for_each_posed_shape(geometry, body, X_WB, point_on_line_W, u_W,
                       [&](int s, const CollisionShape& shape, const Pose& X_WG, const Vector3& o_G,
                           const Vector3& u_G) {
                         HitSink sink(buffer);
                         collect_hits(shape, o_G, u_G, sink);
                         if (sink.distinct() == 0) return;
                         result.num_hits += sink.distinct();
                         const bool is_mesh = shape.type == ShapeType::kMesh;
                         if (!result.hit || sink.first().lambda < result.entry.lambda)
                           result.entry = hit_in_world(sink.first(), X_WG, u_W, is_mesh, -1.0, s);
                         if (!result.hit || sink.last().lambda > result.exit.lambda)
                           result.exit = hit_in_world(sink.last(), X_WG, u_W, is_mesh, 1.0, s);
                         result.hit = true;
                       });

  if (result.hit) {
    result.closest_point_W = result.entry.point_W;
    result.closest_lambda = result.entry.lambda;
    result.distance = 0.0;
    result.shape = result.entry.shape;
    return result;
  }
  if (on_miss == OnMiss::kNothing) return result;
  for_each_posed_shape(geometry, body, X_WB, point_on_line_W, u_W,
                       [&](int s, const CollisionShape& shape, const Pose& X_WG, const Vector3& o_G,
                           const Vector3& u_G) {
                         const ShapeClosestPoint cp = closest_on_miss(shape, o_G, u_G);
                         if (!(cp.distance < result.distance)) return;
                         result.distance = cp.distance;
                         result.closest_point_W = X_WG.act(cp.point_G);
                         result.closest_lambda = cp.lambda;
                         result.shape = s;
                       });
  return result;
}

bool first_entry_on_body(const GeometryModel& geometry, int body, const Pose& X_WB,
                         const Vector3& point_on_line_W, const Vector3& direction_W,
                         double max_lambda, LineHit& entry) noexcept {
  Vector3 u_W;
  if (!usable_line(X_WB, point_on_line_W, direction_W, u_W)) return false;
  if (body < 0 || body >= static_cast<int>(geometry.body_shapes.size())) return false;
  bool hit = false;
  // Only each shape's first hit is wanted: HitSink tracks it whatever its buffer holds.
  std::array<ShapeHit, 1> buffer;
  for_each_posed_shape(geometry, body, X_WB, point_on_line_W, u_W,
                       [&](int s, const CollisionShape& shape, const Pose& X_WG, const Vector3& o_G,
                           const Vector3& u_G) {
                         HitSink sink(buffer);
                         // Beyond the entry found so far this shape cannot come first.
                         collect_hits(shape, o_G, u_G, sink, true,
                                      hit ? std::min(max_lambda, entry.lambda) : max_lambda);
                         if (sink.distinct() == 0) return;
                         if (!hit || sink.first().lambda < entry.lambda)
                           entry = hit_in_world(sink.first(), X_WG, u_W,
                                                shape.type == ShapeType::kMesh, -1.0, s);
                         hit = true;
                       });
  return hit;
}

void warm_up_geometry(const GeometryModel& geometry) noexcept {
  const Pose X_WB;             // identity: the body's own frame
  volatile double sink = 0.0;  // keeps the queries from being optimised away
  for (const CollisionShape& shape : geometry.shapes) {
    if (shape.body < 0 || shape.body >= static_cast<int>(geometry.body_shapes.size())) continue;
    Vector3 centre_S = Vector3::Zero();
    if (shape.type == ShapeType::kMesh && shape.mesh != nullptr &&
        shape.mesh->vertices.cols() > 0) {
      centre_S = shape.mesh->vertices.rowwise().mean();
    }
    const Vector3 centre_B = shape.placement.act(centre_S);
    for (int axis = 0; axis < 3; ++axis) {
      const Vector3 u = Vector3::Unit(axis);
      const SurfacePointResult through =
          intersect_line_with_body(geometry, shape.body, X_WB, centre_B, u);
      LineHit entry;
      const bool entered =
          first_entry_on_body(geometry, shape.body, X_WB, centre_B, u, kInf, entry);
      sink = sink + through.entry.lambda + (entered ? entry.lambda : 0.0);
    }
    // A line far outside every shape: the nearest-point search of a miss.
    const SurfacePointResult miss = intersect_line_with_body(
        geometry, shape.body, X_WB, centre_B + Vector3(1e3, 0.0, 0.0), Vector3::UnitZ());
    sink = sink + miss.distance;
  }
}

}  // namespace extwrench
