#include "mjcf_detail.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <memory>

#include "extwrench/core/error.hpp"
#include "extwrench/io/mesh.hpp"

namespace extwrench::mujoco::mjcf_detail {

Matrix3 quat_rotation(const mjtNum* quat) {
  return Eigen::Quaterniond(quat[0], quat[1], quat[2], quat[3]).normalized().toRotationMatrix();
}

Pose pose(const mjtNum* pos, const mjtNum* quat) {
  Pose X;
  X.rotation = quat_rotation(quat);
  X.translation = vec3(pos);
  return X;
}

Pose pose_from_matrix(const mjtNum* pos, const mjtNum* mat) {
  Pose X;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) X.rotation(i, j) = mat[3 * i + j];
    X.translation[i] = pos[i];
  }
  return X;
}

std::string body_name(const mjModel* m, int b) {
  const char* name = mj_id2name(m, mjOBJ_BODY, b);
  if (name != nullptr && name[0] != '\0') return name;
  return b == 0 ? "world" : "body" + std::to_string(b);
}

std::string joint_name(const mjModel* m, int j) {
  const char* name = mj_id2name(m, mjOBJ_JOINT, j);
  return name != nullptr && name[0] != '\0' ? name : "joint" + std::to_string(j);
}

std::string joint_type_name(int type) {
  switch (type) {
    case mjJNT_FREE:
      return "free";
    case mjJNT_BALL:
      return "ball";
    case mjJNT_SLIDE:
      return "slide";
    case mjJNT_HINGE:
      return "hinge";
    default:
      return "unknown";
  }
}

std::string model_name(const mjModel* m) { return m->nnames > 0 ? std::string(m->names) : ""; }

std::string top_level_names(const mjModel* m) {
  constexpr int kMaxShown = 8;
  std::string names;
  int shown = 0, hidden = 0;
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_parentid[b] != 0) continue;
    if (shown == kMaxShown) {
      ++hidden;
      continue;
    }
    names += (shown++ == 0 ? "'" : ", '") + body_name(m, b) + "'";
  }
  if (hidden > 0) names += " and " + std::to_string(hidden) + " more";
  return shown == 0 ? "none" : names;
}

bool is_in_subtree(const mjModel* m, int ancestor, int b) {
  for (; b > 0; b = m->body_parentid[b]) {
    if (b == ancestor) return true;
  }
  return ancestor == 0;
}

namespace {

std::string geom_where(const mjModel* m, const std::string& file, int b, int g) {
  const char* name = mj_id2name(m, mjOBJ_GEOM, g);
  const std::string geom = name != nullptr && name[0] != '\0'
                               ? "geom '" + std::string(name) + "'"
                               : "geom #" + std::to_string(g - m->body_geomadr[b]);
  return file + ": " + geom + " of body '" + body_name(m, b) + "'";
}

// The capsule along the ellipsoid's longest semi-axis L with radius r = the largest other one
// and half-length L - r holds the ellipsoid (the distance to the segment is at most r).
void ellipsoid_to_capsule(const Vector3& semi_axes, CollisionShape& s) {
  Eigen::Index longest = 0;
  semi_axes.maxCoeff(&longest);
  double radius = 0.0;
  for (Eigen::Index i = 0; i < 3; ++i) {
    if (i != longest) radius = std::max(radius, semi_axes[i]);
  }
  s.type = ShapeType::kCapsule;
  s.radius = radius;
  s.length = 2.0 * std::max(semi_axes[longest] - radius, 0.0);
  // Shapes run along z: turn the longest axis onto it.
  if (longest == 0) s.placement.rotation *= Eigen::AngleAxisd(M_PI / 2, Vector3::UnitY()).matrix();
  if (longest == 1) s.placement.rotation *= Eigen::AngleAxisd(-M_PI / 2, Vector3::UnitX()).matrix();
}

}  // namespace

void collect_geoms(const mjModel* m, const std::string& file, int b, std::vector<GeomSpec>& geoms) {
  for (int g = m->body_geomadr[b]; g >= 0 && g < m->body_geomadr[b] + m->body_geomnum[b]; ++g) {
    if (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0) continue;  // visual only
    // The world's planes and height fields are the ground, not part of a robot rooted there.
    if (b == 0 && (m->geom_type[g] == mjGEOM_PLANE || m->geom_type[g] == mjGEOM_HFIELD)) continue;
    GeomSpec spec;
    spec.body = body_name(m, b);
    spec.source = geom_where(m, file, b, g);
    CollisionShape& s = spec.shape;
    s.placement = pose(m->geom_pos + 3 * g, m->geom_quat + 4 * g);
    const Vector3 size = vec3(m->geom_size + 3 * g);
    switch (m->geom_type[g]) {
      case mjGEOM_SPHERE:
        s.type = ShapeType::kSphere;
        s.radius = size[0];
        break;
      case mjGEOM_CAPSULE:
      case mjGEOM_CYLINDER:
        // MuJoCo's size is (radius, half-length); ours the full length without the caps.
        s.type = m->geom_type[g] == mjGEOM_CAPSULE ? ShapeType::kCapsule : ShapeType::kCylinder;
        s.radius = size[0];
        s.length = 2.0 * size[1];
        break;
      case mjGEOM_BOX:
        s.type = ShapeType::kBox;
        s.size = 2.0 * size;  // MuJoCo: half sides
        break;
      case mjGEOM_ELLIPSOID:
        ellipsoid_to_capsule(size, s);
        break;
      case mjGEOM_MESH:
        s.type = ShapeType::kMesh;
        spec.mesh = m->geom_dataid[g];
        break;
      default:
        throw Error(spec.source + ": unsupported collision geom type '" +
                    (m->geom_type[g] == mjGEOM_PLANE    ? std::string("plane")
                     : m->geom_type[g] == mjGEOM_HFIELD ? std::string("hfield")
                                                        : std::to_string(m->geom_type[g])) +
                    "'" +
                    " on a robot link (expected sphere, capsule, cylinder, box, ellipsoid or mesh; "
                    "set contype=\"0\" conaffinity=\"0\" to make it visual only)");
    }
    geoms.push_back(std::move(spec));
  }
}

namespace {

std::shared_ptr<const TriangleMesh> mesh_of(const mjModel* m, int id, const std::string& source,
                                            const LoadOptions& options) {
  const char* name = mj_id2name(m, mjOBJ_MESH, id);
  const std::string label = name ? std::string(name) : "mesh" + std::to_string(id);
  const int vert = m->mesh_vertadr[id], nvert = m->mesh_vertnum[id];
  const int face = m->mesh_faceadr[id], nface = m->mesh_facenum[id];
  if (!options.load_meshes) {
    auto mesh = std::make_shared<TriangleMesh>();
    mesh->path = label;
    mesh->vertices.resize(3, 0);
    mesh->triangles.resize(3, 0);
    return mesh;
  }
  Matrix3X vertices(3, nvert);
  for (int v = 0; v < nvert; ++v) {
    for (int i = 0; i < 3; ++i) vertices(i, v) = m->mesh_vert[3 * (vert + v) + i];
  }
  Eigen::Matrix<int, 3, Eigen::Dynamic> triangles(3, nface);
  for (int f = 0; f < nface; ++f) {
    for (int i = 0; i < 3; ++i) triangles(i, f) = m->mesh_face[3 * (face + f) + i];
  }
  try {
    return make_triangle_mesh(std::move(vertices), std::move(triangles), label);
  } catch (const Error& e) {
    throw Error(source + ": " + e.what());
  }
}

}  // namespace

GeometryModel build_geometry(const mjModel* m, const Model& model,
                             const std::vector<GeomSpec>& geoms, const LoadOptions& options) {
  GeometryModel geometry;
  geometry.body_shapes.resize(static_cast<std::size_t>(model.num_bodies()));
  std::map<int, std::shared_ptr<const TriangleMesh>> meshes;
  for (const GeomSpec& spec : geoms) {
    CollisionShape shape = shape_on_frame(model, spec.shape, spec.body, spec.source);
    if (shape.type == ShapeType::kMesh) {
      auto& mesh = meshes[spec.mesh];
      if (!mesh) mesh = mesh_of(m, spec.mesh, spec.source, options);
      shape.mesh = mesh;
    }
    geometry.add(std::move(shape));
  }
  return geometry;
}

}  // namespace extwrench::mujoco::mjcf_detail
