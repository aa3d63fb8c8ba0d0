#include "extwrench/estimation/localization.hpp"

#include <cmath>

#include "extwrench/geometry/ray.hpp"

namespace extwrench {

void locate_on_surface(const GeometryModel& geometry, int link, const Pose& X_WL,
                       ContactEstimate& out, std::uint32_t& flags, Vector3& normal_W,
                       const LineHit* known_entry) noexcept {
  const auto l = static_cast<std::size_t>(link);
  if (geometry.body_shapes[l].empty()) {
    flags |= EstimateFlag::kNoGeometry;
    return;
  }
  SurfacePointResult res;
  if (known_entry != nullptr) {
    res.hit = true;
    res.entry = *known_entry;
  } else {
    res = intersect_line_with_body(geometry, link, X_WL, out.line_point_W, out.line_direction_W);
  }
  if (res.hit) {
    out.point_W = res.entry.point_W;  // smallest λ: the pushing point (21)
    out.surface_distance = 0.0;
    normal_W = res.entry.normal_W;
    flags |= EstimateFlag::kSurfacePoint;
  } else if (std::isfinite(res.distance)) {
    out.point_W = res.closest_point_W;  // the line misses the link: nearest surface point
    out.surface_distance = res.distance;
    flags |= EstimateFlag::kSurfaceMissed;
  } else {
    flags |= EstimateFlag::kNoGeometry;
    return;
  }
  out.point_L.noalias() = X_WL.rotation.transpose() * (out.point_W - X_WL.translation);
}

}  // namespace extwrench
