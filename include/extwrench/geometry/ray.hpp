// Intersection of a line of action with a link's collision geometry: places the contact point
// on the surface (the line of action (21), docs/method.md). See docs/geometry.md.
//
// The line is p(λ) = p₀ + λ u with u = d/‖d‖, λ ∈ R in metres along u. For a force F̂ applied by
// a pusher, u = F̂/‖F̂‖ and the pusher comes from −u: the smallest λ on the surface is the
// pushing point (the usual accidental contact), the largest the pulling one.
//
// Everything here is real-time safe: noexcept, no heap allocation, bounded time (O(1) for
// primitives; for meshes O(triangles crossed) with a MeshRayCaster, else O(triangles)).
#pragma once

#include <span>

#include "extwrench/core/types.hpp"
#include "extwrench/geometry/mesh_ray_caster.hpp"
#include "extwrench/geometry/shapes.hpp"

namespace extwrench {

/// One intersection of a line with the surface of a shape, in the shape frame G.
struct ShapeHit {
  double lambda = 0.0;                ///< λ [m] along the unit direction
  Vector3 point_G = Vector3::Zero();  ///< p_G: the surface point p(λ)
  Vector3 normal_G =
      Vector3::Zero();  ///< outward unit normal (meshes: from the triangle's winding)
};

/// The surface point of a shape nearest to a line, in the shape frame G.
struct ShapeClosestPoint {
  Vector3 point_G = Vector3::Zero();  ///< on the surface
  double lambda = 0.0;                ///< λ of the line point nearest to `point_G`
  double distance = 0.0;              ///< [m] ≥ 0; 0 when the line meets the surface
};

/// All intersections of the line origin_G + λ direction_G (direction_G a unit vector, both in
/// the shape frame) with the surface of `shape`, sorted by increasing λ; coincident hits (a mesh
/// edge shared by two triangles) are merged. A convex primitive gives 0 or 2 hits (1 for a tangent
/// line). Writes at most hits.size() hits (the smallest λ first) and returns
/// how many it wrote. A mesh shape without a mesh gives 0.
/// Meshes use mesh->ray_caster when present (candidates refined in double precision against
/// each triangle), else a double-precision loop over all triangles.
[[nodiscard]] int intersect_line_with_shape(const CollisionShape& shape, const Vector3& origin_G,
                                            const Vector3& direction_G,
                                            std::span<ShapeHit> hits) noexcept;

/// The surface point of `shape` nearest to the line origin_G + λ direction_G (unit direction,
/// shape frame). If the line meets the surface: its first (smallest λ) hit, distance 0.
/// Spheres and capsules in closed form; boxes and cylinders by a bounded golden-section search
/// of the convex line-to-solid distance (64 iterations); meshes exactly, from
/// the triangle edges (for a line that misses a triangle, the nearest point of the triangle is
/// on an edge). A mesh shape without a mesh gives distance = +inf.
[[nodiscard]] ShapeClosestPoint closest_point_to_line(const CollisionShape& shape,
                                                      const Vector3& origin_G,
                                                      const Vector3& direction_G) noexcept;

/// One intersection of the line with a body's surface, in the world frame W.
struct LineHit {
  double lambda = 0.0;                 ///< λ [m] along the unit direction
  Vector3 point_W = Vector3::Zero();   ///< p(λ) on the surface
  Vector3 normal_W = Vector3::Zero();  ///< outward unit normal
  int shape = -1;                      ///< index into GeometryModel::shapes
};

/// Result of intersect_line_with_body. On failure or miss, entry/exit are NaN with shape −1.
struct SurfacePointResult {
  bool hit = false;  ///< the line crosses (or touches) a shape of the body
  /// Intersections over all shapes (2 for one convex shape). Past 32 crossings of one shape,
  /// coincident ones may be counted twice; entry and exit stay exact.
  int num_hits = 0;
  LineHit entry;  ///< smallest λ: the pushing point (21)
  LineHit exit;   ///< largest λ: the pulling point
  /// Hit: the entry point, distance 0. Miss: the surface point nearest to the line, with the
  /// line's λ there and the distance [m] (+inf if the body has no usable shape; NaN if the
  /// direction is zero or an input is not finite).
  Vector3 closest_point_W = Vector3::Zero();
  double closest_lambda = 0.0;
  double distance = 0.0;
  int shape = -1;  ///< shape of closest_point_W
};

/// What intersect_line_with_body computes when the line misses every shape of the body.
enum class OnMiss {
  kNearestPoint,  ///< the surface point nearest to the line (a search over every triangle)
  kNothing,       ///< only hit/miss: distance +inf, closest point NaN (isolation's query)
};

/// Intersects the line p(λ) = point_on_line_W + λ direction_W/‖direction_W‖ (21) with every
/// collision shape of `body` (posed at X_WB = pose of the body in W; each shape at
/// X_WB · placement) and returns the smallest-λ hit (pushing point) and the largest-λ hit
/// (pulling point) over all of them, or, if the line misses them all, the nearest surface point
/// (unless `on_miss` is OnMiss::kNothing).
/// Mesh entry/exit normals are oriented against/along u (correct for closed meshes whatever
/// their winding). A zero or non-finite direction, or a body index outside body_shapes, gives
/// hit = false. Real-time safe: noexcept, no allocation, bounded time.
[[nodiscard]] SurfacePointResult intersect_line_with_body(
    const GeometryModel& geometry, int body, const Pose& X_WB, const Vector3& point_on_line_W,
    const Vector3& direction_W, OnMiss on_miss = OnMiss::kNearestPoint) noexcept;

/// The entry of the same line (its smallest-λ crossing with the shapes of `body`) for a caller
/// that compares entries up to a bound, as isolation does: false when the line crosses no shape
/// at λ ≤ max_lambda; else the entry, the same as intersect_line_with_body's whenever that lies
/// at λ ≤ max_lambda (bit for bit, but where two triangles are crossed within float rounding of
/// each other either may be the one reported); a crossing beyond the bound may be returned or
/// not. Cheaper: meshes are searched by a closest-hit traversal, only up to the bound and the
/// nearest entry found so far, and no exit is sought.
/// Real-time safe: noexcept, no allocation, bounded time.
[[nodiscard]] bool first_entry_on_body(const GeometryModel& geometry, int body, const Pose& X_WB,
                                       const Vector3& point_on_line_W, const Vector3& direction_W,
                                       double max_lambda, LineHit& entry) noexcept;

/// Runs the line queries above once against every collision shape (through each shape's centre
/// along the body's three axes, and one line that misses it), results discarded, so that the
/// code they use (the primitives, the mesh caster: Embree's traversal kernels) is paged in
/// before a real-time loop rather than at the first contact. ContactEstimator's constructor
/// calls it; call it (or ContactEstimator::warm_up) again on the loop's thread before the loop,
/// and after an idle phase long enough for the kernel to reclaim pages when memory is not
/// locked (docs/estimator.md#hard-real-time). Measured on the Panda's meshes: the first contact's
/// update otherwise pays 4–5 page faults in libembree, 36–50 µs instead of 5–16 µs (BENCHMARKS.md).
/// noexcept, no allocation; bounded: 7 queries per shape.
void warm_up_geometry(const GeometryModel& geometry) noexcept;

}  // namespace extwrench
