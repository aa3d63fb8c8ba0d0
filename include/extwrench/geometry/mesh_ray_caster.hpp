// Acceleration structure for line queries on a triangle mesh. The core library only sees this
// interface; the io library implements it with Embree (make_embree_ray_caster, io/mesh.hpp).
#pragma once

#include "extwrench/core/types.hpp"

namespace extwrench {

/// Finds the triangles of a mesh that an infinite line may cross. It only *selects* candidates
/// (in single precision, say); the caller refines each one in double precision against the
/// triangle itself, so an implementation may report false positives near edges but must not
/// miss a triangle the line crosses (a watertight test reports at least one of the triangles
/// sharing an edge that the line crosses).
class MeshRayCaster {
 public:
  /// Called once per candidate triangle (index into TriangleMesh::triangles' columns) with the
  /// `user` pointer given to for_each_line_candidate. Must not throw.
  using Visitor = void (*)(void* user, int triangle) noexcept;

  MeshRayCaster() = default;
  MeshRayCaster(const MeshRayCaster&) = delete;
  MeshRayCaster& operator=(const MeshRayCaster&) = delete;
  virtual ~MeshRayCaster() = default;

  /// Visits every triangle crossed by the line p(λ) = origin + λ direction, λ ∈ R (both
  /// directions), in the mesh frame. `direction` is a unit vector. Each triangle is visited at
  /// least once (possibly more), in no particular order.
  /// Real-time safe: const, noexcept, allocation-free, callable from several threads at once.
  virtual void for_each_line_candidate(const Vector3& origin, const Vector3& direction,
                                       Visitor visit, void* user) const noexcept = 0;

  /// Called like Visitor; returns whether the caller found the triangle crossed (its exact
  /// test), which lets the caster skip every triangle beyond that crossing. Must not throw.
  using CrossingVisitor = bool (*)(void* user, int triangle) noexcept;

  /// For a caller after the first crossing at λ ≤ max_lambda (a line's entry, up to a bound):
  /// visits every triangle crossed at λ ≤ max_lambda that lies before, or within rounding of,
  /// each crossing `visit` confirmed; triangles beyond may be visited or not. The default
  /// visits the whole line; an implementation prunes the rest.
  virtual void for_each_first_crossing_candidate(const Vector3& origin, const Vector3& direction,
                                                 double max_lambda, CrossingVisitor visit,
                                                 void* user) const noexcept {
    static_cast<void>(max_lambda);
    struct Adapter {
      CrossingVisitor visit;
      void* user;
    } adapter{visit, user};
    for_each_line_candidate(
        origin, direction,
        [](void* a, int triangle) noexcept {
          const auto* ad = static_cast<const Adapter*>(a);
          static_cast<void>(ad->visit(ad->user, triangle));
        },
        &adapter);
  }
};

}  // namespace extwrench
