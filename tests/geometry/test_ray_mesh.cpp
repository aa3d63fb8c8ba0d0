// Meshes: loading (assimp), Embree candidate selection + double refinement, brute force, and
// the Panda collision meshes. Checked against the analytic box, an independent half-space
// computation for convex polyhedra, and an independent line/triangle solve.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/geometry/ray.hpp"
#include "extwrench/io/mesh.hpp"
#include "geometry/mesh_files.hpp"
#include "geometry/shape_checks.hpp"
#include "support/alloc_counter.hpp"
#include "support/error_of.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

using test::SeededRng;

// Double refinement against exactly stored vertices: only rounding remains.
constexpr double kExactTolerance = 1e-9;
// The Panda requirement: the pushing point within 1e-5 m.
constexpr double kPandaTolerance = 1e-5;

Vector3 random_unit(SeededRng& rng) {
  for (;;) {
    const Vector3 v = rng.uniform_vector3(-1.0, 1.0);
    if (v.norm() > 0.1 && v.norm() <= 1.0) return v.normalized();
  }
}

CollisionShape mesh_shape(std::shared_ptr<const TriangleMesh> mesh) {
  CollisionShape s;
  s.type = ShapeType::kMesh;
  s.mesh = std::move(mesh);
  return s;
}

/// The same triangles without a ray caster: intersect_line_with_shape then loops over them.
CollisionShape brute_force_copy(const CollisionShape& s) {
  auto copy = std::make_shared<TriangleMesh>(*s.mesh);
  copy->ray_caster = nullptr;
  return mesh_shape(copy);
}

/// Independent line/triangle solve: o + λu = v0 + b1 e1 + b2 e2 as a 3×3 linear system.
bool solve_line_triangle(const TriangleMesh& m, Eigen::Index t, const Vector3& o, const Vector3& u,
                         double& lambda) {
  const Vector3 v0 = m.vertices.col(m.triangles(0, t));
  Matrix3 a;
  a.col(0) = -u;
  a.col(1) = m.vertices.col(m.triangles(1, t)) - v0;
  a.col(2) = m.vertices.col(m.triangles(2, t)) - v0;
  if (std::abs(a.determinant()) < 1e-14 * a.col(1).cross(a.col(2)).norm()) return false;
  const Vector3 x = a.partialPivLu().solve(o - v0);
  if (x[1] < -1e-9 || x[2] < -1e-9 || x[1] + x[2] > 1.0 + 1e-9) return false;
  lambda = x[0];
  return true;
}

/// Line ∩ convex polyhedron as the intersection of the half-spaces of its faces (Cyrus–Beck):
/// independent of any triangle test. Returns false if empty.
bool convex_interval(const TriangleMesh& m, const Vector3& o, const Vector3& u, double& entry,
                     double& exit) {
  entry = -std::numeric_limits<double>::infinity();
  exit = std::numeric_limits<double>::infinity();
  for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
    const Vector3 v0 = m.vertices.col(m.triangles(0, t));
    const Vector3 n =
        (m.vertices.col(m.triangles(1, t)) - v0).cross(m.vertices.col(m.triangles(2, t)) - v0);
    const double nu = n.dot(u), dist = n.dot(v0 - o);  // inside: n·(o + λu − v0) ≤ 0
    if (nu == 0.0) {
      if (dist < 0.0) return false;
      continue;
    }
    const double l = dist / nu;
    if (nu < 0.0)
      entry = std::max(entry, l);
    else
      exit = std::min(exit, l);
  }
  return entry <= exit;
}

double signed_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
    v += m.vertices.col(m.triangles(0, t))
             .dot(m.vertices.col(m.triangles(1, t)).cross(m.vertices.col(m.triangles(2, t))));
  }
  return v / 6.0;
}

TEST(RayMesh, GeneratedBoxFromAnStlFileMatchesTheAnalyticBox) {
  const Vector3 size(0.5, 0.25, 0.75), centre(0.125, -0.25, 0.5);  // exact in float
  const test::TempFile file("box.stl");
  test::write_ascii_stl(test::box_mesh(size, centre), file.path());
  const CollisionShape mesh = mesh_shape(load_mesh(file.path()));
  ASSERT_NE(mesh.mesh->ray_caster, nullptr);
  EXPECT_EQ(mesh.mesh->triangles.cols(), 12);
  EXPECT_EQ(mesh.mesh->vertices.cols(), 8);  // identical vertices joined
  EXPECT_NEAR(signed_volume(*mesh.mesh), size.prod(), 1e-15);
  const CollisionShape brute = brute_force_copy(mesh);
  const CollisionShape box = test::make_box(size);

  SeededRng rng(21);
  int hitting = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vector3 o = centre + rng.uniform_vector3(-1.0, 1.0);
    const Vector3 u = random_unit(rng);
    std::array<ShapeHit, 8> expected, embree, loop;
    const int n = intersect_line_with_shape(box, o - centre, u, expected);
    const int n_embree = intersect_line_with_shape(mesh, o, u, embree);
    const int n_loop = intersect_line_with_shape(brute, o, u, loop);
    ASSERT_EQ(n_embree, n) << "trial " << trial;
    ASSERT_EQ(n_loop, n) << "trial " << trial;
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      EXPECT_NEAR(embree[k].lambda, expected[k].lambda, kExactTolerance);
      EXPECT_LT((embree[k].point_G - (expected[k].point_G + centre)).norm(), kExactTolerance);
      EXPECT_LT((embree[k].normal_G - expected[k].normal_G).norm(), 1e-12);
      EXPECT_NEAR(loop[k].lambda, expected[k].lambda, kExactTolerance);
    }
    hitting += n > 0;
  }
  EXPECT_GT(hitting, 200);
}

TEST(RayMesh, IcosphereFromAnObjFileMatchesItsHalfSpaceDescription) {
  const test::SimpleMesh sphere = test::icosphere_mesh(0.25, 2);
  const test::TempFile file("icosphere.obj");
  test::write_obj(sphere, file.path());
  const CollisionShape mesh = mesh_shape(load_mesh(file.path()));
  EXPECT_EQ(mesh.mesh->triangles.cols(), 320);
  EXPECT_GT(signed_volume(*mesh.mesh), 0.0);
  const CollisionShape brute = brute_force_copy(mesh);

  SeededRng rng(22);
  int hitting = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vector3 o = rng.uniform_vector3(-0.4, 0.4);
    const Vector3 u = random_unit(rng);
    double entry = 0.0, exit = 0.0;
    const bool expected_hit = convex_interval(*mesh.mesh, o, u, entry, exit);
    std::array<ShapeHit, 8> embree, loop;
    const int n = intersect_line_with_shape(mesh, o, u, embree);
    const int n_loop = intersect_line_with_shape(brute, o, u, loop);
    ASSERT_EQ(n, expected_hit ? 2 : 0) << "trial " << trial;
    ASSERT_EQ(n_loop, n);
    if (n == 2) {
      EXPECT_NEAR(embree[0].lambda, entry, kExactTolerance);
      EXPECT_NEAR(embree[1].lambda, exit, kExactTolerance);
      EXPECT_NEAR(loop[0].lambda, entry, kExactTolerance);
      EXPECT_NEAR(loop[1].lambda, exit, kExactTolerance);
      EXPECT_LT(embree[0].normal_G.dot(u), 0.0);
      EXPECT_GT(embree[1].normal_G.dot(u), 0.0);
      ++hitting;
    }
  }
  EXPECT_GT(hitting, 500);
}

TEST(RayMesh, ScaleIsAppliedPerAxisAndMirroringKeepsNormalsOutward) {
  const Vector3 size(0.5, 0.25, 0.75);
  const test::TempFile file("box_scaled.stl");
  test::write_ascii_stl(test::box_mesh(size), file.path());
  for (const Vector3& scale : {Vector3(2.0, 1.0, 0.5), Vector3(-2.0, 1.0, 0.5)}) {
    SCOPED_TRACE(scale.transpose());
    const CollisionShape mesh = mesh_shape(load_mesh(file.path(), scale));
    EXPECT_NEAR(signed_volume(*mesh.mesh), size.prod() * std::abs(scale.prod()), 1e-15);
    std::array<ShapeHit, 4> hits;
    ASSERT_EQ(intersect_line_with_shape(mesh, Vector3(-3.0, 0.01, 0.02), Vector3::UnitX(), hits),
              2);
    EXPECT_NEAR(hits[0].point_G.x(), -0.5, 1e-15);  // 0.25 × |2|
    EXPECT_NEAR(hits[1].point_G.x(), 0.5, 1e-15);
    EXPECT_LT((hits[0].normal_G + Vector3::UnitX()).norm(), 1e-15);
    EXPECT_LT((hits[1].normal_G - Vector3::UnitX()).norm(), 1e-15);
  }
}

TEST(RayMesh, LinesThroughSharedEdgesAndCornersCountEachCrossingOnce) {
  const Vector3 size(0.5, 0.25, 0.75);
  const test::SimpleMesh box = test::box_mesh(size);
  const CollisionShape embree =
      mesh_shape(make_triangle_mesh(test::vertex_matrix(box), test::triangle_matrix(box), "box"));
  const CollisionShape brute = brute_force_copy(embree);
  const Vector3 h = 0.5 * size;
  struct Line {
    Vector3 o, u;
    double entry, exit;
  };
  const Line lines[] = {
      // Through the face centres: on the diagonal shared by each face's two triangles.
      {Vector3(-2.0, 0.0, 0.0), Vector3::UnitX(), 2.0 - h.x(), 2.0 + h.x()},
      {Vector3(0.0, 0.0, 2.0), -Vector3::UnitZ(), 2.0 - h.z(), 2.0 + h.z()},
      // Through two opposite corners, where three faces (up to six triangles) meet.
      {-2.0 * h, h.normalized(), h.norm(), 3.0 * h.norm()},
  };
  for (const CollisionShape* shape : {&embree, &brute}) {
    for (const Line& line : lines) {
      std::array<ShapeHit, 8> hits;
      ASSERT_EQ(intersect_line_with_shape(*shape, line.o, line.u, hits), 2);
      EXPECT_NEAR(hits[0].lambda, line.entry, 1e-12);
      EXPECT_NEAR(hits[1].lambda, line.exit, 1e-12);
    }
  }
}

TEST(RayMesh, ManyCrossingsKeepTheSmallestInTheBufferAndTheExtremesInTheBodyQuery) {
  // 40 unit-spaced cubes in a row along x, in one mesh: a line along x crosses it 80 times.
  test::SimpleMesh row;
  for (int i = 0; i < 40; ++i) {
    const test::SimpleMesh cube = test::box_mesh(Vector3(0.5, 0.5, 0.5), Vector3(i, 0.0, 0.0));
    const int offset = static_cast<int>(row.vertices.size());
    row.vertices.insert(row.vertices.end(), cube.vertices.begin(), cube.vertices.end());
    for (const auto& t : cube.triangles)
      row.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  GeometryModel g;
  g.shapes = {
      mesh_shape(make_triangle_mesh(test::vertex_matrix(row), test::triangle_matrix(row), "row"))};
  g.body_shapes = {{0}};
  const Vector3 o(-10.0, 0.1, -0.05);
  std::array<ShapeHit, 8> hits;
  ASSERT_EQ(intersect_line_with_shape(g.shapes[0], o, Vector3::UnitX(), hits), 8);
  for (int i = 0; i < 8; ++i) {
    // Cube k spans x ∈ [k − 0.25, k + 0.25]: crossings at 10 + k ∓ 0.25.
    EXPECT_NEAR(hits[static_cast<std::size_t>(i)].lambda, 10.0 + i / 2 + (i % 2 ? 0.25 : -0.25),
                1e-12);
  }
  const SurfacePointResult r =
      intersect_line_with_body(g, 0, Pose::identity(), o, Vector3::UnitX());
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.num_hits, 80);
  EXPECT_NEAR(r.entry.lambda, 9.75, 1e-12);
  EXPECT_NEAR(r.exit.lambda, 49.25, 1e-12);
}

TEST(RayMesh, LoadingErrorsNameTheFile) {
  const std::filesystem::path missing =
      std::filesystem::temp_directory_path() / "extwrench_no_such_mesh.stl";
  const std::string missing_error = test::error_of([&] { (void)load_mesh(missing); });
  EXPECT_NE(missing_error.find(missing.string()), std::string::npos) << missing_error;
  const test::TempFile empty("points_only.obj");
  {
    std::ofstream out(empty.path());
    out << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  }
  const std::string empty_error = test::error_of([&] { (void)load_mesh(empty.path()); });
  EXPECT_NE(empty_error.find(empty.path().string()), std::string::npos) << empty_error;
  EXPECT_THROW(
      (void)make_triangle_mesh(Matrix3X::Zero(3, 3), Eigen::Matrix<int, 3, 1>(0, 1, 3), "bad"),
      Error);
  // Only degenerate triangles (collinear points, a repeated vertex): no surface to hit.
  const test::TempFile flat("degenerate_only.obj");
  {
    std::ofstream out(flat.path());
    out << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 4 1\n";
  }
  const std::string flat_error = test::error_of([&] { (void)load_mesh(flat.path()); });
  EXPECT_NE(flat_error.find(flat.path().string()), std::string::npos) << flat_error;
  EXPECT_NE(flat_error.find("all 2 triangles are degenerate"), std::string::npos) << flat_error;
}

std::vector<std::filesystem::path> panda_meshes() {
  const std::filesystem::path dir = std::filesystem::path(EXTWRENCH_SHARED_DIR) /
                                    "models/franka_panda/urdf_example-robot-data/meshes/collision";
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".stl") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(RayMeshPanda, PushingPointIsRecoveredForInwardLinesThroughSurfacePoints) {
  const auto files = panda_meshes();
  if (files.empty())
    GTEST_SKIP() << "Panda collision meshes not found under " << EXTWRENCH_SHARED_DIR;
  SeededRng rng(23);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    const CollisionShape shape = mesh_shape(load_mesh(file));
    const TriangleMesh& m = *shape.mesh;
    ASSERT_GT(signed_volume(m), 0.0) << "winding not outward";
    int tested = 0;
    for (int trial = 0; trial < 400; ++trial) {
      // A random point on a random triangle, a random direction into the surface there.
      const auto t = static_cast<Eigen::Index>(
          rng.uniform(0.0, static_cast<double>(m.triangles.cols()) - 1e-9));
      double b1 = rng.uniform(0.0, 1.0), b2 = rng.uniform(0.0, 1.0);
      if (b1 + b2 > 1.0) {
        b1 = 1.0 - b1;
        b2 = 1.0 - b2;
      }
      const Vector3 v0 = m.vertices.col(m.triangles(0, t));
      const Vector3 e1 = m.vertices.col(m.triangles(1, t)) - v0,
                    e2 = m.vertices.col(m.triangles(2, t)) - v0;
      if (e1.cross(e2).norm() < 1e-12) continue;
      const Vector3 q = v0 + b1 * e1 + b2 * e2;
      const Vector3 n = e1.cross(e2).normalized();
      const Vector3 u = random_unit(rng);
      if (u.dot(n) > -0.05) continue;
      const double s = rng.uniform(-0.2, 0.2);
      const Vector3 o = q + s * u;  // q is at λ = −s
      // A pusher reaches q from −u only if nothing of the link lies before it on the line.
      bool reachable = true;
      for (Eigen::Index k = 0; k < m.triangles.cols() && reachable; ++k) {
        double l = 0.0;
        if (solve_line_triangle(m, k, o, u, l) && l < -s - 1e-7) reachable = false;
      }
      if (!reachable) continue;
      ++tested;
      const Pose X_WB =
          Pose::from_xyz_rpy(rng.uniform_vector3(-1.0, 1.0), rng.uniform_vector3(-3.0, 3.0));
      GeometryModel geometry;
      geometry.shapes = {shape};
      geometry.body_shapes = {{0}};
      const SurfacePointResult r =
          intersect_line_with_body(geometry, 0, X_WB, X_WB.act(o), X_WB.rotation * u);
      ASSERT_TRUE(r.hit);
      EXPECT_LT((r.entry.point_W - X_WB.act(q)).norm(), kPandaTolerance);
      EXPECT_NEAR(r.entry.lambda, -s, kPandaTolerance);
      EXPECT_LT(r.entry.normal_W.dot(X_WB.rotation * u), 0.0);
      // The pulling point is a different, later crossing.
      EXPECT_GT(r.exit.lambda, r.entry.lambda);
      EXPECT_GE(r.num_hits, 2);
    }
    EXPECT_GT(tested, 100);
  }
}

TEST(RayMeshPanda, MissesReportTheExactDistanceToTheMesh) {
  const auto files = panda_meshes();
  if (files.empty())
    GTEST_SKIP() << "Panda collision meshes not found under " << EXTWRENCH_SHARED_DIR;
  SeededRng rng(24);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    GeometryModel geometry;
    geometry.shapes = {mesh_shape(load_mesh(file))};
    geometry.body_shapes = {{0}};
    const TriangleMesh& m = *geometry.shapes[0].mesh;
    for (int trial = 0; trial < 50; ++trial) {
      // The vertex v* extreme along w supports the plane w·x = w·v*; a line in the plane
      // w·x = w·v* + d through v* + d w is exactly d away from the mesh.
      const Vector3 w = random_unit(rng);
      Eigen::Index best = 0;
      (w.transpose() * m.vertices).maxCoeff(&best);
      const Vector3 v = m.vertices.col(best);
      const double d = rng.uniform(0.001, 0.1);
      const Vector3 u = w.cross(random_unit(rng)).normalized();
      const Vector3 o = v + d * w + rng.uniform(-0.3, 0.3) * u;
      const SurfacePointResult r = intersect_line_with_body(geometry, 0, Pose::identity(), o, u);
      ASSERT_FALSE(r.hit);
      EXPECT_EQ(r.num_hits, 0);
      EXPECT_NEAR(r.distance, d, 1e-12);
      EXPECT_NEAR(w.dot(r.closest_point_W), w.dot(v), 1e-12);
      EXPECT_NEAR((o + r.closest_lambda * u - r.closest_point_W).norm(), d, 1e-12);
      EXPECT_EQ(r.shape, 0);
      EXPECT_TRUE(std::isnan(r.entry.lambda));
    }
  }
}

TEST(RayMeshPanda, QueriesFromSeveralThreadsAgreeWithSequentialOnes) {
  const auto files = panda_meshes();
  if (files.empty())
    GTEST_SKIP() << "Panda collision meshes not found under " << EXTWRENCH_SHARED_DIR;
  const CollisionShape shape = mesh_shape(load_mesh(files.front()));
  SeededRng rng(25);
  std::vector<Vector3> origins, directions;
  for (int i = 0; i < 2000; ++i) {
    origins.push_back(rng.uniform_vector3(-0.15, 0.15));
    directions.push_back(random_unit(rng));
  }
  const auto run = [&](std::vector<double>& out) {
    std::array<ShapeHit, 16> hits;
    for (std::size_t i = 0; i < origins.size(); ++i) {
      const int n = intersect_line_with_shape(shape, origins[i], directions[i], hits);
      out[i] = n > 0 ? hits[0].lambda + 100.0 * n : -1.0;
    }
  };
  std::vector<double> sequential(origins.size()), a(origins.size()), b(origins.size());
  run(sequential);
  std::thread ta([&] { run(a); });
  std::thread tb([&] { run(b); });
  ta.join();
  tb.join();
  EXPECT_EQ(a, sequential);
  EXPECT_EQ(b, sequential);
}

// The ray caster's first-crossing search (for_each_first_crossing_candidate) visits the line's
// first crossing whenever it lies at λ ≤ the bound (a brute-force solve of every triangle says
// where), however much it prunes, and nothing at all when the mesh lies beyond the bound.
TEST(RayMeshPanda, TheFirstCrossingSearchVisitsTheFirstCrossingUpToTheBound) {
  const auto files = panda_meshes();
  if (files.empty())
    GTEST_SKIP() << "Panda collision meshes not found under " << EXTWRENCH_SHARED_DIR;
  SeededRng rng(27);
  const CollisionShape shape = mesh_shape(load_mesh(files.back()));
  const TriangleMesh& m = *shape.mesh;
  const Vector3 lower = m.vertices.rowwise().minCoeff(), upper = m.vertices.rowwise().maxCoeff();
  struct Search {
    const TriangleMesh* mesh;
    Vector3 o, u;
    int visits = 0;
    double first = std::numeric_limits<double>::infinity();  // of the confirmed crossings
  };
  const auto visit = [](void* user, int triangle) noexcept {
    auto& s = *static_cast<Search*>(user);
    ++s.visits;
    double lambda = 0.0;
    if (!solve_line_triangle(*s.mesh, triangle, s.o, s.u, lambda)) return false;
    s.first = std::min(s.first, lambda);
    return true;
  };
  int within = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vector3 u = random_unit(rng);
    const Vector3 through = lower + (upper - lower).cwiseProduct(rng.uniform_vector3(0.2, 0.8));
    const Vector3 o = through - rng.uniform(0.0, 0.5) * u;
    double first = std::numeric_limits<double>::infinity();
    for (Eigen::Index t = 0; t < m.triangles.cols(); ++t) {
      double lambda = 0.0;
      if (solve_line_triangle(m, t, o, u, lambda)) first = std::min(first, lambda);
    }
    const double bound = rng.uniform(-0.1, 0.6);
    Search search{&m, o, u};
    m.ray_caster->for_each_first_crossing_candidate(o, u, bound, visit, &search);
    if (first <= bound) {
      ++within;
      EXPECT_NEAR(search.first, first, 1e-9) << "trial " << trial;
    }
  }
  EXPECT_GT(within, 100);
  // A bound before the line reaches the mesh's box: no candidate; beyond it: some.
  const Vector3 u = Vector3::UnitX();
  const Vector3 o(lower.x() - 1.0, 0.5 * (lower.y() + upper.y()), 0.5 * (lower.z() + upper.z()));
  Search before{&m, o, u};
  m.ray_caster->for_each_first_crossing_candidate(o, u, 0.5, visit, &before);
  EXPECT_EQ(before.visits, 0);
  Search after{&m, o, u};
  m.ray_caster->for_each_first_crossing_candidate(o, u, 1.0 + (upper.x() - lower.x()), visit,
                                                  &after);
  EXPECT_GT(after.visits, 0);
}

// first_entry_on_body gives intersect_line_with_body's entry, bit for bit, whenever that lies
// within the bound; no entry where the line misses; never a point before the entry. A body of
// two Panda meshes, so the second shape is searched only up to the first one's entry.
TEST(RayMeshPanda, TheFirstEntryUpToABoundIsTheBodyQuerysEntry) {
  const auto files = panda_meshes();
  if (files.size() < 2)
    GTEST_SKIP() << "Panda collision meshes not found under " << EXTWRENCH_SHARED_DIR;
  SeededRng rng(28);
  GeometryModel geometry;
  geometry.shapes = {mesh_shape(load_mesh(files[files.size() - 2])),
                     mesh_shape(load_mesh(files.back()))};
  geometry.shapes[1].placement = Pose::from_xyz_rpy(Vector3(0.05, -0.03, 0.08), Vector3(0.3, 0, 1));
  geometry.body_shapes = {{0, 1}};
  int within = 0, beyond = 0, missed = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const Pose X_WB =
        Pose::from_xyz_rpy(rng.uniform_vector3(-1.0, 1.0), rng.uniform_vector3(-3.0, 3.0));
    const Vector3 u = X_WB.rotation * random_unit(rng);
    const Vector3 p = X_WB.act(rng.uniform_vector3(-0.1, 0.15)) - rng.uniform(0.0, 0.4) * u;
    const SurfacePointResult full = intersect_line_with_body(geometry, 0, X_WB, p, 2.0 * u);
    const double bound = full.hit ? full.entry.lambda + rng.uniform(-0.05, 0.05) : 0.3;
    LineHit entry;
    const bool found = first_entry_on_body(geometry, 0, X_WB, p, 2.0 * u, bound, entry);
    if (!full.hit) {
      EXPECT_FALSE(found);
      ++missed;
      continue;
    }
    if (full.entry.lambda <= bound) {
      ++within;
      ASSERT_TRUE(found);
      EXPECT_EQ(entry.lambda, full.entry.lambda);
      EXPECT_EQ(entry.point_W, full.entry.point_W);
      EXPECT_EQ(entry.normal_W, full.entry.normal_W);
      EXPECT_EQ(entry.shape, full.entry.shape);
    } else {
      ++beyond;
      if (found) {
        EXPECT_GE(entry.lambda, full.entry.lambda);
      }
    }
  }
  EXPECT_GT(within, 100);
  EXPECT_GT(beyond, 100);
  EXPECT_GT(missed, 50);
}

TEST(RayMesh, EmbreeQueriesDoNotAllocate) {
  if (!test::allocation_counting_available()) GTEST_SKIP() << "allocation counting unavailable";
  const test::SimpleMesh sphere = test::icosphere_mesh(0.25, 2);
  GeometryModel geometry;
  geometry.shapes = {mesh_shape(
      make_triangle_mesh(test::vertex_matrix(sphere), test::triangle_matrix(sphere), "icosphere"))};
  geometry.body_shapes = {{0}};
  SeededRng rng(26);
  std::vector<Vector3> origins, directions;
  for (int i = 0; i < 500; ++i) {
    origins.push_back(rng.uniform_vector3(-0.5, 0.5));
    directions.push_back(random_unit(rng));
  }
  const Pose X_WB = Pose::from_xyz_rpy(Vector3(0.1, 0.2, 0.3), Vector3(0.4, 0.5, 0.6));
  // Warm-up: Embree may set up per-thread state on a thread's first query.
  (void)intersect_line_with_body(geometry, 0, X_WB, origins[0], directions[0]);
  int hits = 0, misses = 0;
  const test::AllocationCounter counter;
  for (std::size_t i = 0; i < origins.size(); ++i) {
    const SurfacePointResult r =
        intersect_line_with_body(geometry, 0, X_WB, origins[i], directions[i]);
    (r.hit ? hits : misses) += 1;
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_GT(hits, 50);
  EXPECT_GT(misses, 50);
}

}  // namespace
}  // namespace extwrench
