// Independent descriptions of the primitive shapes for the geometry tests: implicit functions
// (negative inside, zero on the surface) and point-to-solid distances, written from the
// definitions, not from the code under test.
#pragma once

#include <algorithm>
#include <cmath>

#include "extwrench/geometry/shapes.hpp"

namespace extwrench::test {

inline CollisionShape make_sphere(double r) {
  CollisionShape s;
  s.type = ShapeType::kSphere;
  s.radius = r;
  return s;
}
inline CollisionShape make_box(const Vector3& size) {
  CollisionShape s;
  s.type = ShapeType::kBox;
  s.size = size;
  return s;
}
inline CollisionShape make_cylinder(double r, double length) {
  CollisionShape s;
  s.type = ShapeType::kCylinder;
  s.radius = r;
  s.length = length;
  return s;
}
inline CollisionShape make_capsule(double r, double length) {
  CollisionShape s;
  s.type = ShapeType::kCapsule;
  s.radius = r;
  s.length = length;
  return s;
}

/// Implicit function of a primitive (shape frame): < 0 inside, 0 on the surface, > 0 outside.
inline double implicit(const CollisionShape& s, const Vector3& p) {
  switch (s.type) {
    case ShapeType::kSphere:
      return p.norm() - s.radius;
    case ShapeType::kBox:
      return (p.cwiseAbs() - 0.5 * s.size).maxCoeff();
    case ShapeType::kCylinder:
      return std::max(std::hypot(p.x(), p.y()) - s.radius, std::abs(p.z()) - 0.5 * s.length);
    case ShapeType::kCapsule: {
      const double z = std::clamp(p.z(), -0.5 * s.length, 0.5 * s.length);
      return (p - Vector3(0.0, 0.0, z)).norm() - s.radius;
    }
    case ShapeType::kMesh:
      break;
  }
  return NAN;
}

/// Euclidean distance from a point to the solid (0 inside).
inline double distance_to_solid(const CollisionShape& s, const Vector3& p) {
  switch (s.type) {
    case ShapeType::kSphere:
      return std::max(p.norm() - s.radius, 0.0);
    case ShapeType::kBox: {
      const Vector3 h = 0.5 * s.size;
      return (p - p.cwiseMax(-h).cwiseMin(h)).norm();
    }
    case ShapeType::kCylinder: {
      const double dr = std::max(std::hypot(p.x(), p.y()) - s.radius, 0.0);
      const double dz = std::max(std::abs(p.z()) - 0.5 * s.length, 0.0);
      return std::hypot(dr, dz);
    }
    case ShapeType::kCapsule:
      return std::max(implicit(s, p), 0.0);
    case ShapeType::kMesh:
      break;
  }
  return NAN;
}

/// Radius of a ball about the origin containing the shape.
inline double bounding_radius(const CollisionShape& s) {
  switch (s.type) {
    case ShapeType::kSphere:
      return s.radius;
    case ShapeType::kBox:
      return 0.5 * s.size.norm();
    case ShapeType::kCylinder:
      return std::hypot(s.radius, 0.5 * s.length);
    case ShapeType::kCapsule:
      return s.radius + 0.5 * s.length;
    case ShapeType::kMesh:
      break;
  }
  return NAN;
}

/// Outward normal from central differences of the implicit function; false at a ridge (edge
/// of a box, rim of a cylinder) where forward and backward differences disagree.
inline bool numerical_normal(const CollisionShape& s, const Vector3& p, Vector3& n) {
  constexpr double kStep = 1e-7;
  Vector3 forward, backward;
  const double f0 = implicit(s, p);
  for (int i = 0; i < 3; ++i) {
    const Vector3 e = kStep * Vector3::Unit(i);
    forward[i] = (implicit(s, p + e) - f0) / kStep;
    backward[i] = (f0 - implicit(s, p - e)) / kStep;
  }
  if ((forward - backward).norm() > 1e-3) return false;
  n = (forward + backward).normalized();
  return true;
}

/// A surface point found by bisection of the implicit function along the ray from the centre
/// in direction w (the primitives are star-shaped about their origin).
inline Vector3 surface_point_towards(const CollisionShape& s, const Vector3& w) {
  double lo = 0.0, hi = 2.0 * bounding_radius(s) + 1.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (implicit(s, mid * w) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi) * w;
}

}  // namespace extwrench::test
