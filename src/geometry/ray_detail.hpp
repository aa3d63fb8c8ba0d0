// Private to src/geometry: what the three parts of the line / surface intersection share (the
// primitives in ray_primitives.cpp, meshes in ray_mesh.cpp, bodies in ray.cpp). All in shape
// frame: o = a point on the line, u = its unit direction.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "extwrench/geometry/ray.hpp"

namespace extwrench::ray_detail {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

// Hits of one shape closer than this along the line are one hit (an edge shared by two mesh
// triangles is found twice). Far below any physical contact resolution.
inline constexpr double kSameHitLambda = 1e-10;  // [m]

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

/// Hits of a sphere, box, cylinder or capsule (none for a mesh) into out[0..3]; returns the count.
int primitive_hits(const CollisionShape& shape, const Vector3& o, const Vector3& u,
                   ShapeHit* out) noexcept;
/// Surface point of a primitive nearest to a line that misses it.
ShapeClosestPoint primitive_closest_on_miss(const CollisionShape& shape, const Vector3& o,
                                            const Vector3& u) noexcept;

/// Every hit of the line with a triangle mesh into `sink`.
void mesh_hits(const TriangleMesh& mesh, const Vector3& o, const Vector3& u,
               HitSink& sink) noexcept;
/// The hits a first-crossing search needs into `sink`: its first() is the line's first hit at
/// λ ≤ max_lambda (if any; with a ray caster, up to float rounding between crossings closer
/// than that); other hits may be missing.
void mesh_first_hits(const TriangleMesh& mesh, const Vector3& o, const Vector3& u, HitSink& sink,
                     double max_lambda) noexcept;
/// Surface point of a mesh nearest to a line that misses it.
ShapeClosestPoint mesh_closest_on_miss(const TriangleMesh& m, const Vector3& o,
                                       const Vector3& u) noexcept;

}  // namespace extwrench::ray_detail
