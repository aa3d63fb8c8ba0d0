// Meshes generated in the tests (a box, an icosphere), written to temporary STL / OBJ files so
// that the whole path file → assimp → Embree is exercised. Coordinates are chosen exactly
// representable in float, because assimp reads in single precision.
#pragma once

#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "extwrench/core/types.hpp"

namespace extwrench::test {

struct SimpleMesh {
  std::vector<Vector3> vertices;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

/// Box with full sides `size` centred at `centre`, 12 triangles, oriented outward (checked
/// against the face normal while building, not assumed).
inline SimpleMesh box_mesh(const Vector3& size, const Vector3& centre = Vector3::Zero()) {
  SimpleMesh m;
  const Vector3 h = 0.5 * size;
  for (int i = 0; i < 8; ++i) {
    m.vertices.emplace_back(centre + Vector3((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                                             (i & 4) ? h.z() : -h.z()));
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (const int side : {0, 1}) {
      std::vector<int> face;  // the 4 corners with this coordinate, in cyclic order
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      for (const auto& [ca, cb] :
           {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}, std::pair{0, 1}}) {
        face.push_back((side << axis) | (ca << a) | (cb << b));
      }
      const Vector3 outward = (side ? 1.0 : -1.0) * Vector3::Unit(axis);
      std::array<int, 3> t1{face[0], face[1], face[2]}, t2{face[0], face[2], face[3]};
      const Vector3& v0 = m.vertices[static_cast<std::size_t>(face[0])];
      const Vector3 n = (m.vertices[static_cast<std::size_t>(face[1])] - v0)
                            .cross(m.vertices[static_cast<std::size_t>(face[2])] - v0);
      if (n.dot(outward) < 0.0) {
        std::swap(t1[1], t1[2]);
        std::swap(t2[1], t2[2]);
      }
      m.triangles.push_back(t1);
      m.triangles.push_back(t2);
    }
  }
  return m;
}

/// Icosahedron subdivided `levels` times, vertices on the sphere of radius r, rounded to float.
inline SimpleMesh icosphere_mesh(double r, int levels) {
  const double t = 0.5 * (1.0 + std::sqrt(5.0));
  SimpleMesh m;
  for (const Vector3& v :
       {Vector3(-1, t, 0), Vector3(1, t, 0), Vector3(-1, -t, 0), Vector3(1, -t, 0),
        Vector3(0, -1, t), Vector3(0, 1, t), Vector3(0, -1, -t), Vector3(0, 1, -t),
        Vector3(t, 0, -1), Vector3(t, 0, 1), Vector3(-t, 0, -1), Vector3(-t, 0, 1)}) {
    m.vertices.push_back(v.normalized());
  }
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    const auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      m.vertices.push_back(
          (m.vertices[static_cast<std::size_t>(a)] + m.vertices[static_cast<std::size_t>(b)])
              .normalized());
      const int id = static_cast<int>(m.vertices.size()) - 1;
      midpoint[key] = id;
      return id;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& [a, b, c] : m.triangles) {
      const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.triangles = std::move(next);
  }
  for (Vector3& v : m.vertices) v = (r * v).cast<float>().cast<double>();
  return m;
}

inline Matrix3X vertex_matrix(const SimpleMesh& m) {
  Matrix3X v(3, static_cast<Eigen::Index>(m.vertices.size()));
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    v.col(static_cast<Eigen::Index>(i)) = m.vertices[i];
  return v;
}

inline Eigen::Matrix<int, 3, Eigen::Dynamic> triangle_matrix(const SimpleMesh& m) {
  Eigen::Matrix<int, 3, Eigen::Dynamic> t(3, static_cast<Eigen::Index>(m.triangles.size()));
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      t(k, static_cast<Eigen::Index>(i)) = m.triangles[i][static_cast<std::size_t>(k)];
  }
  return t;
}

/// A file in the temporary directory, removed when the object goes out of scope.
class TempFile {
 public:
  explicit TempFile(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("extwrench_" + std::to_string(::getpid()) + "_" + name)) {}
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void write_ascii_stl(const SimpleMesh& m, const std::filesystem::path& path) {
  std::ofstream out(path);
  out << std::setprecision(17) << "solid generated\n";
  for (const auto& t : m.triangles) {
    const Vector3& a = m.vertices[static_cast<std::size_t>(t[0])];
    const Vector3& b = m.vertices[static_cast<std::size_t>(t[1])];
    const Vector3& c = m.vertices[static_cast<std::size_t>(t[2])];
    const Vector3 n = (b - a).cross(c - a).normalized();
    out << "facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n outer loop\n";
    for (const Vector3* v : {&a, &b, &c})
      out << "  vertex " << v->x() << ' ' << v->y() << ' ' << v->z() << '\n';
    out << " endloop\nendfacet\n";
  }
  out << "endsolid generated\n";
}

inline void write_obj(const SimpleMesh& m, const std::filesystem::path& path) {
  std::ofstream out(path);
  out << std::setprecision(17);
  for (const Vector3& v : m.vertices) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : m.triangles)
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

}  // namespace extwrench::test
