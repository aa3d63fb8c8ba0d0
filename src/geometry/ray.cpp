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

void collect_hits(const CollisionShape& shape, const Vector3& o, const Vector3& u,
                  HitSink& sink) noexcept {
  if (shape.type == ShapeType::kMesh) {
    if (shape.mesh != nullptr) mesh_hits(*shape.mesh, o, u, sink);
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

  const auto to_shape = [&](const CollisionShape& shape, Pose& X_WG, Vector3& o_G, Vector3& u_G) {
    X_WG = X_WB * shape.placement;
    o_G.noalias() = X_WG.rotation.transpose() * (point_on_line_W - X_WG.translation);
    u_G.noalias() = X_WG.rotation.transpose() * u_W;
  };

  std::array<ShapeHit, kMaxHitsPerShape> buffer;
  for (const int s : geometry.body_shapes[static_cast<std::size_t>(body)]) {
    if (s < 0 || s >= num_shapes) continue;
    const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
    Pose X_WG;
    Vector3 o_G, u_G;
    to_shape(shape, X_WG, o_G, u_G);
    HitSink sink(buffer);
    collect_hits(shape, o_G, u_G, sink);
    if (sink.distinct() == 0) continue;
    result.num_hits += sink.distinct();
    const bool is_mesh = shape.type == ShapeType::kMesh;
    const auto to_world = [&](const ShapeHit& h, double orient) {
      LineHit w{h.lambda, X_WG.act(h.point_G), X_WG.rotation * h.normal_G, s};
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
  if (on_miss == OnMiss::kNothing) return result;
  for (const int s : geometry.body_shapes[static_cast<std::size_t>(body)]) {
    if (s < 0 || s >= num_shapes) continue;
    const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
    Pose X_WG;
    Vector3 o_G, u_G;
    to_shape(shape, X_WG, o_G, u_G);
    const ShapeClosestPoint cp = closest_on_miss(shape, o_G, u_G);
    if (cp.distance < result.distance) {
      result.distance = cp.distance;
      result.closest_point_W = X_WG.act(cp.point_G);
      result.closest_lambda = cp.lambda;
      result.shape = s;
    }
  }
  return result;
}

}  // namespace extwrench
