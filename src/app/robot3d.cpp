#include "robot3d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"

namespace extwrench::detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kBlocks = 8;            // data blocks (gnuplot indices) per snapshot
constexpr int kCircleSegments = 24;   // polygon of a drawn circle
constexpr int kMeshTriangles = 300;   // triangles drawn per mesh, at most (every k-th)
constexpr double kArrowLength = 0.3;  // [m] of the largest force drawn

// The extent of everything written, for the axes' ranges.
struct Bounds {
  Vector3 lo = Vector3::Constant(-0.3);
  Vector3 hi = Vector3::Constant(0.3);
  void add(const Vector3& p) {
    if (!p.allFinite()) return;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
};

struct Writer {
  std::ostream& out;
  Bounds& bounds;
  void point(const Vector3& p) {
    out << p.x() << " " << p.y() << " " << p.z() << "\n";
    bounds.add(p);
  }
  void end_line() { out << "\n"; }     // a break between segments of one block
  void end_block() { out << "\n\n"; }  // the next gnuplot index
  void empty_block() { out << "NaN NaN NaN\n\n\n"; }
};

// A circle of radius r about c in the plane of the unit vectors u, v (world frame).
void circle(Writer& w, const Vector3& c, const Vector3& u, const Vector3& v, double r,
            double from = 0.0, double to = 2.0 * std::numbers::pi) {
  for (int k = 0; k <= kCircleSegments; ++k) {
    const double a = from + (to - from) * k / kCircleSegments;
    w.point(c + r * (std::cos(a) * u + std::sin(a) * v));
  }
  w.end_line();
}

void segment(Writer& w, const Vector3& a, const Vector3& b) {
  w.point(a);
  w.point(b);
  w.end_line();
}

void box(Writer& w, const Pose& X, const Vector3& size) {
  const Vector3 h = size / 2;
  auto corner = [&](int i) {
    return X.act(Vector3(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z()));
  };
  for (int i = 0; i < 8; ++i) {
    for (const int bit : {1, 2, 4}) {
      if ((i & bit) == 0) segment(w, corner(i), corner(i | bit));
    }
  }
}

// Cylinder (caps = false) or capsule along the shape's z axis.
void round_shape(Writer& w, const Pose& X, double r, double length, bool caps) {
  const Vector3 ex = X.rotation.col(0), ey = X.rotation.col(1), ez = X.rotation.col(2);
  const Vector3 top = X.act(Vector3(0, 0, length / 2)), bottom = X.act(Vector3(0, 0, -length / 2));
  circle(w, top, ex, ey, r);
  circle(w, bottom, ex, ey, r);
  for (int k = 0; k < 4; ++k) {
    const double a = k * std::numbers::pi / 2;
    const Vector3 d = r * (std::cos(a) * ex + std::sin(a) * ey);
    segment(w, bottom + d, top + d);
  }
  if (!caps) return;
  for (const Vector3& side : {ex, ey}) {
    circle(w, top, side, ez, r, 0.0, std::numbers::pi);
    circle(w, bottom, side, -ez, r, 0.0, std::numbers::pi);
  }
}

void primitive(Writer& w, const CollisionShape& shape, const Pose& X) {
  switch (shape.type) {
    case ShapeType::kSphere:
      circle(w, X.translation, X.rotation.col(0), X.rotation.col(1), shape.radius);
      circle(w, X.translation, X.rotation.col(1), X.rotation.col(2), shape.radius);
      circle(w, X.translation, X.rotation.col(2), X.rotation.col(0), shape.radius);
      break;
    case ShapeType::kBox:
      box(w, X, shape.size);
      break;
    case ShapeType::kCylinder:
    case ShapeType::kCapsule:
      round_shape(w, X, shape.radius, shape.length, shape.type == ShapeType::kCapsule);
      break;
    case ShapeType::kMesh:
      break;  // drawn as points (mesh_points)
  }
}

// Blocks 1 and 2 of a snapshot: the primitives' wireframes, outlines of the meshes' triangles.
void shapes_blocks(Writer& w, const GeometryModel* geometry, const Data& data) {
  bool any = false;
  for (const CollisionShape& s : geometry ? geometry->shapes : std::vector<CollisionShape>{}) {
    if (s.type == ShapeType::kMesh) continue;
    primitive(w, s, data.X_WB[static_cast<std::size_t>(s.body)] * s.placement);
    any = true;
  }
  any ? w.end_block() : w.empty_block();
  any = false;
  for (const CollisionShape& s : geometry ? geometry->shapes : std::vector<CollisionShape>{}) {
    if (s.type != ShapeType::kMesh || !s.mesh) continue;
    const Pose X = data.X_WB[static_cast<std::size_t>(s.body)] * s.placement;
    // A sample of the triangles as outlines: unlike vertices (at a tube's ends only), their
    // edges follow the whole surface.
    const auto& v = s.mesh->vertices;
    const Eigen::Index count = s.mesh->triangles.cols();
    const Eigen::Index step =
        std::max<Eigen::Index>(1, (count + kMeshTriangles - 1) / kMeshTriangles);
    for (Eigen::Index t = 0; t < count; t += step) {
      for (int k = 0; k <= 3; ++k) w.point(X.act(v.col(s.mesh->triangles(k % 3, t))));
      w.end_line();
    }
    any = true;
  }
  any ? w.end_block() : w.empty_block();
}

Vector3 at(const double* row, int column) {
  return {row[column], row[column + 1], row[column + 2]};
}

// The arrow of a force f ending at p (the force pushes the link at p): "x y z dx dy dz".
void arrow_block(Writer& w, const Vector3& p, const Vector3& f, double scale) {
  if (!p.allFinite() || !f.allFinite() || f.norm() == 0.0) {
    w.out << "NaN NaN NaN NaN NaN NaN\n\n\n";
    return;
  }
  const Vector3 d = f * scale;
  const Vector3 tail = p - d;
  w.bounds.add(tail);
  w.out << tail.x() << " " << tail.y() << " " << tail.z() << " " << d.x() << " " << d.y() << " "
        << d.z() << "\n\n\n";
}

// Where the estimated force is drawn: its surface point, else p̂.
Vector3 force_point(const double* row) {
  const Vector3 p = at(row, kP);
  return p.allFinite() ? p : at(row, kL);
}

// One snapshot's kBlocks blocks: skeleton (sensor, then body origins), primitives, mesh
// points, true point, line of action (± 0.3 m about p̂), estimated point, estimated force,
// true force.
void write_snapshot(Writer& w, const Robot3dInput& in, Data& data, const double* row,
                    double scale) {
  const int n = in.model.nq();
  VectorX q(n);
  for (int i = 0; i < n; ++i) q[i] = row[joint_col(kPosition, n, i)];
  forward_kinematics(in.model, data, q);
  w.point(in.p_WS);
  for (int b = 0; b < in.model.num_bodies(); ++b)
    w.point(data.X_WB[static_cast<std::size_t>(b)].translation);
  w.end_block();
  shapes_blocks(w, in.geometry, data);
  const bool touched = in.truth && row[kTrueContact] > 0.5;
  touched ? (w.point(at(row, kPt)), w.end_block()) : w.empty_block();
  if (at(row, kL).allFinite() && at(row, kDir).allFinite()) {
    segment(w, at(row, kL) - 0.3 * at(row, kDir), at(row, kL) + 0.3 * at(row, kDir));
    w.end_block();
  } else {
    w.empty_block();
  }
  at(row, kP).allFinite() ? (w.point(at(row, kP)), w.end_block()) : w.empty_block();
  arrow_block(w, force_point(row), at(row, kF), scale);
  arrow_block(w, touched ? at(row, kPt) : Vector3::Constant(kNaN), at(row, kFt), scale);
}

// The rows shown: `count` at the middles of equal slices of the rows in contact (estimated or
// true), or of all rows when none is.
std::vector<int> snapshot_rows(const Decimator& rows, int count) {
  std::vector<int> contact, all;
  for (int i = 0; i < rows.rows(); ++i) {
    all.push_back(i);
    if (rows.row(i)[kContact] > 0.5 || rows.row(i)[kTrueContact] > 0.5) contact.push_back(i);
  }
  const std::vector<int>& pool = contact.empty() ? all : contact;
  std::vector<int> shots;
  const auto available = static_cast<long long>(pool.size());
  const long long k_max = std::max(1LL, std::min<long long>(count, available));
  for (long long k = 0; k < k_max && available > 0; ++k)
    shots.push_back(pool[static_cast<std::size_t>(((available - 1) * (2 * k + 1)) / (2 * k_max))]);
  return shots;
}

// Metres of arrow per newton: the largest force among the snapshots is kArrowLength long.
double arrow_scale(const Decimator& rows, const std::vector<int>& shots) {
  double f_max = 0.0;
  for (const int r : shots) {
    for (const int c : {kF, kFt}) {
      const Vector3 f = at(rows.row(r), c);
      if (f.allFinite()) f_max = std::max(f_max, f.norm());
    }
  }
  return f_max > 0.0 ? kArrowLength / f_max : 0.0;
}

std::string robot3d_script(const PlotContext& c, const Figure& f, const Robot3dInput& in,
                           const std::vector<int>& shots, const Bounds& b, double scale) {
  std::ostringstream s;
  const int cols = shots.size() > 1 ? 2 : 1;
  const int lines = std::max(1, static_cast<int>((shots.size() + 1) / 2));
  const double half = 0.5 * (b.hi - b.lo).maxCoeff() + 0.05;
  const Vector3 mid = 0.5 * (b.hi + b.lo);
  char arrow[96] = "estimated force";
  if (scale > 0.0)
    std::snprintf(arrow, sizeof arrow, "estimated force (%.2g m = %.3g N)", kArrowLength,
                  kArrowLength / scale);
  // Each view in a cell of its own (origin and size set per view), the title in a band at the
  // top, the key in a band on the right: nothing overlaps. The views start a little right of
  // the canvas's edge: the left column's z label is drawn left of its axis and was cut off.
  const int height = 480 * lines + 40;
  const double top = 40.0 / height, left = 0.025, views_width = 0.76;
  const double cell_w = views_width / cols, cell_h = (1.0 - top) / lines;
  s << gnuplot_preamble(f.output, c.format, 1350, height) << "set multiplot title "
    << gnuplot_quote("Robot (collision shapes), estimated force, line of action and points — " +
                     enhanced(c.title))
    << "\nset view 62,30,1.3\nset view equal xyz\nset ticslevel 0\n";
  for (int k = 0; k < 3; ++k)
    s << "set " << kAxis[k] << "range [" << mid[k] - half << ":" << mid[k] + half << "]\nset "
      << kAxis[k] << "label '" << kAxis[k] << " [m]'\n";
  s << "set key at screen 0.995, screen " << 1.0 - 2.0 * top
    << " right top vertical samplen 2 spacing 1.3\n";
  for (std::size_t k = 0; k < shots.size(); ++k) {
    char t[64];
    std::snprintf(t, sizeof t, "t = %.3f s", in.rows.row(shots[k])[kT] + c.t_offset);
    const auto has = [&](bool mesh) {
      if (in.geometry == nullptr) return false;
      return std::any_of(
          in.geometry->shapes.begin(), in.geometry->shapes.end(),
          [&](const CollisionShape& x) { return (x.type == ShapeType::kMesh) == mesh; });
    };
    const auto title = [&](const char* text, bool shown = true) {
      if (!shown) return std::string("''");
      return k == 0 ? gnuplot_quote(text) : std::string("''");
    };
    const int i = kBlocks * static_cast<int>(k);
    const int row = static_cast<int>(k) / cols, column = static_cast<int>(k) % cols;
    s << "set origin " << left + column * cell_w << ", " << 1.0 - top - (row + 1) * cell_h
      << "\nset size " << cell_w << ", " << cell_h << "\nset title '" << t << "'\n"
      << "splot 'robot3d.txt' index " << i
      << " with linespoints lw 3 pt 7 ps 0.8 lc rgb '#555555' title "
      << title("links (sensor, joint origins)") << ", '' index " << i + 1
      << " with lines lw 1 lc rgb '#8c8c8c' title " << title("collision shapes", has(false))
      << ", '' index " << i + 2 << " with lines lw 0.5 lc rgb '#b0b0b0' title "
      << title("meshes (sampled triangles)", has(true)) << ", '' index " << i + 3
      << " with points pt 7 ps 1.6 lc rgb '#d62728' title " << title("true point") << ", '' index "
      << i + 4 << " with lines lw 3 lc rgb '#1f77b4' title " << title("line of action")
      << ", '' index " << i + 5 << " with points pt 9 ps 1.8 lc rgb '#2ca02c' title "
      << title("estimated point") << ", '' index " << i + 6
      << " using 1:2:3:4:5:6 with vectors head filled lw 3 lc rgb '#ff7f0e' title " << title(arrow)
      << ", '' index " << i + 7
      << " using 1:2:3:4:5:6 with vectors head empty dt 2 lw 2 lc rgb '#d62728' title "
      << title("true force") << "\n";
  }
  s << "unset multiplot\n";
  return s.str();
}

}  // namespace

Figure plot_robot3d(const PlotContext& c, const Robot3dInput& in, OutputFiles& outputs) {
  const Figure f = figure(c, "robot3d");
  const std::vector<int> shots = snapshot_rows(in.rows, in.snapshots);
  const double scale = arrow_scale(in.rows, shots);
  Data data(in.model);
  Bounds bounds;
  bounds.add(in.p_WS);
  const std::filesystem::path txt = c.dir / "robot3d.txt";
  {
    std::ofstream out(outputs.stage(txt));
    Writer w{out, bounds};
    for (const int r : shots) write_snapshot(w, in, data, in.rows.row(r), scale);
    out.flush();
    if (!out) throw Error(txt.string() + ": write failed (disk full?)");
  }
  outputs.commit(txt);
  const std::filesystem::path script = outputs.stage(f.script);
  {
    std::ofstream out(script);
    out << robot3d_script(c, f, in, shots, bounds, scale);
    out.flush();
    if (!out) throw Error(script.string() + ": write failed (disk full?)");
  }
  outputs.commit(f.script);
  return f;
}

}  // namespace extwrench::detail
