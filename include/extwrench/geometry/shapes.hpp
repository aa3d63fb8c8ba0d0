// Collision geometry attached to bodies, used to locate a contact point on a link's surface.
// Kept apart from the Model (as Pinocchio's GeometryModel): dynamics never needs it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "extwrench/core/types.hpp"

namespace extwrench {

enum class ShapeType { kSphere, kBox, kCylinder, kCapsule, kMesh };

/// Line-query acceleration structure for a triangle mesh (implemented with Embree in the io
/// library); the core library only sees this interface.
class MeshRayCaster;

/// Triangle mesh in the shape frame (scale already applied).
struct TriangleMesh {
  std::string path;  ///< file it was loaded from
  Eigen::Matrix<double, 3, Eigen::Dynamic> vertices;
  Eigen::Matrix<int, 3, Eigen::Dynamic> triangles;  ///< vertex indices, counter-clockwise outward
  std::shared_ptr<const MeshRayCaster> ray_caster;  ///< may be null: brute force is used then
};

/// One collision shape. Cylinders and capsules are along the shape frame's z axis, centred on
/// its origin (URDF convention); `length` excludes a capsule's hemispherical caps.
struct CollisionShape {
  ShapeType type = ShapeType::kSphere;
  std::string link;                          ///< URDF link (frame) it was declared on
  int body = 0;                              ///< body it is rigidly attached to
  Pose placement;                            ///< X_{body, shape}
  double radius = 0.0;                       ///< sphere, cylinder, capsule [m]
  double length = 0.0;                       ///< cylinder, capsule [m]
  Vector3 size = Vector3::Zero();            ///< box: full side lengths [m]
  Vector3 scale = Vector3::Ones();           ///< mesh scale as declared
  std::shared_ptr<const TriangleMesh> mesh;  ///< kMesh only
};

/// All collision shapes of a robot, grouped by body.
struct GeometryModel {
  std::vector<CollisionShape> shapes;
  /// Indices into `shapes` for each body (size = model.num_bodies()).
  std::vector<std::vector<int>> body_shapes;

  /// Appends `shape` and indexes it under its body (body_shapes must already hold that body).
  void add(CollisionShape shape);
};

struct Model;

/// A shape declared in the frame `frame` of `model` (its placement in that frame's axes) as it
/// is attached: `link` = frame, `body` = the body carrying the frame, placement composed with
/// the frame's (shapes of links merged by fixed joints move onto the merged body). Every robot
/// loader places its shapes through this. Throws Error "<source>: no link or frame named ..."
/// when the model has no such frame.
CollisionShape shape_on_frame(const Model& model, const CollisionShape& declared,
                              const std::string& frame, const std::string& source);

}  // namespace extwrench
