// Mesh files to TriangleMesh with assimp: all meshes of the scene merged in the file's frame.
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <string>
#include <utility>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/mesh.hpp"

namespace extwrench {
namespace {

struct Soup {
  std::vector<Vector3> vertices;
  std::vector<Eigen::Vector3i> triangles;
};

/// Appends the meshes of `node` and its children, with the node transforms accumulated, so the
/// vertices end up in the file's root frame.
void collect(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, Soup& soup) {
  const aiMatrix4x4 transform = parent * node.mTransformation;
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[m]];
    const int offset = static_cast<int>(soup.vertices.size());
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D p = transform * mesh.mVertices[v];
      soup.vertices.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines bound no volume
      soup.triangles.emplace_back(offset + static_cast<int>(face.mIndices[0]),
                                  offset + static_cast<int>(face.mIndices[1]),
                                  offset + static_cast<int>(face.mIndices[2]));
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c)
    collect(scene, *node.mChildren[c], transform, soup);
}

}  // namespace

std::shared_ptr<const TriangleMesh> make_triangle_mesh(
    Matrix3X vertices, Eigen::Matrix<int, 3, Eigen::Dynamic> triangles, const std::string& name) {
  if (triangles.cols() == 0) throw Error(name + ": mesh has no triangles");
  if (!vertices.allFinite()) throw Error(name + ": mesh has a non-finite vertex coordinate");
  if (triangles.minCoeff() < 0 || triangles.maxCoeff() >= vertices.cols()) {
    throw Error(name + ": triangle vertex index out of range [0, " +
                std::to_string(vertices.cols()) + ")");
  }
  // Some degenerate triangles are harmless; a mesh of nothing else has no surface for a line of
  // action to enter (a broken export), and every isolation on its link would miss silently.
  bool has_area = false;
  for (Eigen::Index t = 0; t < triangles.cols() && !has_area; ++t) {
    const Vector3 a = vertices.col(triangles(0, t));
    has_area =
        (vertices.col(triangles(1, t)) - a).cross(vertices.col(triangles(2, t)) - a).squaredNorm() >
        0.0;
  }
  if (!has_area) {
    throw Error(name + ": mesh has no surface: all " + std::to_string(triangles.cols()) +
                " triangles are degenerate (zero area)");
  }
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->path = name;
  mesh->ray_caster = make_embree_ray_caster(vertices, triangles, name);
  mesh->vertices = std::move(vertices);
  mesh->triangles = std::move(triangles);
  return mesh;
}

std::shared_ptr<const TriangleMesh> load_mesh(const std::filesystem::path& path,
                                              const Vector3& scale) {
  const std::string name = path.string();
  if (!scale.allFinite() || (scale.array() == 0.0).any()) {
    throw Error(name + ": mesh scale must be finite and non-zero");
  }
  // Before assimp opens it: a directory, FIFO or device must not reach the importer.
  check_input_file(path, "mesh", kMaxMeshFileBytes);
  Assimp::Importer importer;
  // URDF tools read Collada in the file's own axes. Normals are dropped (they come from the
  // winding) so that vertices are joined by position alone.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene = importer.ReadFile(
      name, aiProcess_Triangulate | aiProcess_DropNormals | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw Error(name + ": cannot read mesh: " + importer.GetErrorString());
  }
  Soup soup;
  collect(*scene, *scene->mRootNode, aiMatrix4x4(), soup);
  if (soup.triangles.empty()) throw Error(name + ": mesh has no triangles");
  if (soup.triangles.size() > kMaxMeshTriangles) {
    throw Error(name + ": " + std::to_string(soup.triangles.size()) +
                " triangles, more than the limit of " + std::to_string(kMaxMeshTriangles) +
                " (docs/model.md)");
  }

  Matrix3X vertices(3, static_cast<Eigen::Index>(soup.vertices.size()));
  for (std::size_t i = 0; i < soup.vertices.size(); ++i) {
    vertices.col(static_cast<Eigen::Index>(i)) = soup.vertices[i].cwiseProduct(scale);
  }
  Eigen::Matrix<int, 3, Eigen::Dynamic> triangles(3,
                                                  static_cast<Eigen::Index>(soup.triangles.size()));
  for (std::size_t i = 0; i < soup.triangles.size(); ++i) {
    triangles.col(static_cast<Eigen::Index>(i)) = soup.triangles[i];
  }
  // A mirroring scale (odd number of negative factors) turns the winding inward: restore it.
  if (scale.prod() < 0.0) triangles.row(1).swap(triangles.row(2));
  return make_triangle_mesh(std::move(vertices), std::move(triangles), name);
}

}  // namespace extwrench
