// Pushes on the outward-reachable surface of a link (issue 9, acceptance 1): a random point of
// one of the link's shapes (capsules by area, meshes by triangle area), normal to the surface or
// 30° off it, at a random configuration inside the joint limits, kept only when a pusher coming
// along the force reaches the point before any other surface. Shared by the per-sample test
// against KDL (test_geometry_isolation.cpp) and the MuJoCo closed loop (test_mujoco_pushes.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "extwrench/core/random.hpp"
#include "extwrench/geometry/ray.hpp"
#include "extwrench/io/robot_loader.hpp"

namespace extwrench::test {

struct AreaSurfacePoint {
  Vector3 p_B, n_B;  ///< point and outward normal in the body frame
};

/// A random point of a shape's surface (capsules: by area; meshes: triangles by area).
inline AreaSurfacePoint area_weighted_surface_point(const CollisionShape& s, Rng& rng) {
  AreaSurfacePoint out;
  if (s.type == ShapeType::kCapsule) {
    const double cyl = 2.0 * std::numbers::pi * s.radius * s.length;
    const double caps = 4.0 * std::numbers::pi * s.radius * s.radius;
    if (rng.uniform01() * (cyl + caps) < cyl) {
      const double phi = rng.uniform(0.0, 2.0 * std::numbers::pi);
      out.n_B = Vector3(std::cos(phi), std::sin(phi), 0.0);
      out.p_B = s.radius * out.n_B + Vector3(0, 0, rng.uniform(-0.5, 0.5) * s.length);
    } else {
      Vector3 d(rng.normal(), rng.normal(), rng.normal());
      d.normalize();
      out.n_B = d;
      out.p_B = s.radius * d + Vector3(0, 0, (d.z() > 0 ? 0.5 : -0.5) * s.length);
    }
  } else {
    const TriangleMesh& m = *s.mesh;
    std::vector<double> cumulative(static_cast<std::size_t>(m.triangles.cols()));
    double total = 0.0;
    for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
      const Vector3 a = m.vertices.col(m.triangles(0, t)), b = m.vertices.col(m.triangles(1, t)),
                    c = m.vertices.col(m.triangles(2, t));
      total += 0.5 * (b - a).cross(c - a).norm();
      cumulative[static_cast<std::size_t>(t)] = total;
    }
    const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), rng.uniform01() * total);
    const Eigen::Index t = std::min<Eigen::Index>(it - cumulative.begin(), m.triangles.cols() - 1);
    const Vector3 a = m.vertices.col(m.triangles(0, t)), b = m.vertices.col(m.triangles(1, t)),
                  c = m.vertices.col(m.triangles(2, t));
    double u = rng.uniform(0.02, 0.98), v = rng.uniform(0.02, 0.98);
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    out.p_B = a + u * (b - a) + v * (c - a);
    out.n_B = (b - a).cross(c - a).normalized();
  }
  out.p_B = s.placement.act(out.p_B);
  out.n_B = s.placement.rotation * out.n_B;
  return out;
}

struct ReachablePush {
  int link = 0;
  VectorX q;
  Vector3 p_W, u_W;  ///< contact point, unit force direction (into the surface), at q
  Vector3 p_B;       ///< the contact point in the link's frame
};

/// A pusher coming along u reaches p before any surface (p is not hidden by another link, nor
/// by another part of its own link, and does not lie inside another link).
inline bool reachable(const GeometryModel& g, const std::vector<Pose>& X_WB,
                      const ReachablePush& p) {
  for (int b = 0; b < static_cast<int>(g.body_shapes.size()); ++b) {
    if (g.body_shapes[static_cast<std::size_t>(b)].empty()) continue;
    const SurfacePointResult r =
        intersect_line_with_body(g, b, X_WB[static_cast<std::size_t>(b)], p.p_W, p.u_W);
    if (r.hit && r.entry.lambda < -1e-4) return false;
  }
  return true;
}

/// The body poses X_WB of a configuration (from an engine of the test's choice).
using BodyPoses = std::function<std::vector<Pose>(const VectorX& q)>;

/// `count` reachable pushes on `link` at random configurations inside the joint limits (joints
/// without limits: ±2.5 rad), kept 10 % away from each limit; every other one 30° off the normal.
inline std::vector<ReachablePush> make_reachable_pushes(const RobotDescription& robot,
                                                        const BodyPoses& poses, int link, int count,
                                                        Rng& rng) {
  const Model& model = robot.model;
  const GeometryModel& g = robot.geometry;
  const auto& shapes = g.body_shapes[static_cast<std::size_t>(link)];
  std::vector<ReachablePush> pushes;
  for (int attempt = 0; attempt < 5000 && static_cast<int>(pushes.size()) < count; ++attempt) {
    ReachablePush p;
    p.link = link;
    p.q.resize(model.nq());
    for (int i = 0; i < model.nq(); ++i) {
      const Joint& j = model.joints[static_cast<std::size_t>(i + 1)];
      const double lo = std::isfinite(j.lower) ? j.lower : -2.5;
      const double hi = std::isfinite(j.upper) ? j.upper : 2.5;
      p.q[i] = rng.uniform(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo));
    }
    const std::vector<Pose> X_WB = poses(p.q);
    const auto pick = static_cast<std::size_t>(rng.uniform(0.0, shapes.size() - 1e-9));
    const CollisionShape& shape = g.shapes[static_cast<std::size_t>(shapes[pick])];
    const bool sampled = shape.type == ShapeType::kCapsule ||
                         (shape.type == ShapeType::kMesh && shape.mesh != nullptr);
    if (!sampled) continue;  // the arms here have capsules or meshes only
    const AreaSurfacePoint sp = area_weighted_surface_point(shape, rng);
    const Pose& X = X_WB[static_cast<std::size_t>(link)];
    p.p_B = sp.p_B;
    p.p_W = X.act(sp.p_B);
    const Vector3 n_W = X.rotation * sp.n_B;
    p.u_W = -n_W;
    if (pushes.size() % 2 == 1) {  // 30° off the normal, towards a random tangent
      Vector3 t = Vector3(rng.normal(), rng.normal(), rng.normal()).cross(n_W).normalized();
      const double a = 30.0 * std::numbers::pi / 180.0;
      p.u_W = -std::cos(a) * n_W + std::sin(a) * t;
    }
    if (reachable(g, X_WB, p)) pushes.push_back(p);
  }
  return pushes;
}

}  // namespace extwrench::test
