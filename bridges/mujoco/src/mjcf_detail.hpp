// Private helpers of the MJCF reader: names, poses and collision geoms of a compiled mjModel.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "extwrench/geometry/shapes.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::mujoco::mjcf_detail {

inline Vector3 vec3(const mjtNum* p) { return {p[0], p[1], p[2]}; }
/// The rotation of MuJoCo's quaternion (w, x, y, z), normalised.
Matrix3 quat_rotation(const mjtNum* quat);
/// The pose (pos, quat), e.g. X_{body, geom} from geom_pos, geom_quat.
Pose pose(const mjtNum* pos, const mjtNum* quat);
/// The world pose from MuJoCo's position and row-major matrix (xpos/xmat, site_xpos/xmat).
Pose pose_from_matrix(const mjtNum* pos, const mjtNum* mat);
/// X_{parent body, body} at qpos0 (body_pos, body_quat).
inline Pose body_offset(const mjModel* m, int b) {
  return pose(m->body_pos + 3 * b, m->body_quat + 4 * b);
}

/// The body's name, or "body<id>" for an unnamed one; "world" for body 0.
std::string body_name(const mjModel* m, int b);
/// The joint's name, or "joint<id>" for an unnamed one.
std::string joint_name(const mjModel* m, int j);
std::string joint_type_name(int type);
/// The <mujoco model="..."> name (MuJoCo's default "MuJoCo Model" when absent).
std::string model_name(const mjModel* m);
/// "a, b, c" (at most 8 shown): the children of the world body.
std::string top_level_names(const mjModel* m);
/// True when `ancestor` is on the path from the world to `b` (b is its own ancestor).
bool is_in_subtree(const mjModel* m, int ancestor, int b);

/// A collision geom of a body before the Model exists: placement X_{body, geom}.
struct GeomSpec {
  CollisionShape shape;
  std::string body;  ///< the MuJoCo body, a frame of the built model
  int mesh = -1;     ///< MuJoCo mesh id (kMesh)
  std::string source;
};

/// Appends body b's collision geoms (contype or conaffinity non-zero) to `geoms`. Ellipsoids
/// become their bounding capsule (docs/mujoco.md); planes and height fields are refused.
void collect_geoms(const mjModel* m, const std::string& file, int b, std::vector<GeomSpec>& geoms);

/// The GeometryModel of the built model: each geom on the body its MuJoCo body merged into,
/// meshes from MuJoCo's compiled vertices and faces (one TriangleMesh per mesh, with its Embree
/// ray caster; none when !options.load_meshes).
GeometryModel build_geometry(const mjModel* m, const Model& model,
                             const std::vector<GeomSpec>& geoms, const LoadOptions& options);

}  // namespace extwrench::mujoco::mjcf_detail
