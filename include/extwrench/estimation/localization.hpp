// Contact point from the line of action (21): p(λ) = p̂ + λ F̂/‖F̂‖ meets the link's collision
// shapes, and the smallest λ is the pushing point; a line that misses the link gives the
// nearest surface point and its distance.
#pragma once

#include <cstdint>

#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/geometry/ray.hpp"
#include "extwrench/geometry/shapes.hpp"

namespace extwrench {

/// Contact-point stage. In: the geometry, the link, its pose X_WL, and out.line_point_W /
/// out.line_direction_W. Out: out.point_W, out.point_L, out.surface_distance, one of
/// kSurfacePoint, kSurfaceMissed, kNoGeometry in `flags`, and the outward surface normal at a
/// hit (for the point's uncertainty; unchanged otherwise). `known_entry`, when not null, is where
/// this very line enters the link's shapes at X_WL, already computed (by isolation): the shapes
/// are then not queried again. noexcept, no allocation.
void locate_on_surface(const GeometryModel& geometry, int link, const Pose& X_WL,
                       ContactEstimate& out, std::uint32_t& flags, Vector3& normal_W,
                       const LineHit* known_entry = nullptr) noexcept;

}  // namespace extwrench
