#include "loader_detail.hpp"

#include <cstdlib>
#include <system_error>

#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/mesh.hpp"

namespace extwrench::io_detail {

namespace fs = std::filesystem;

namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

bool exists_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

// The last `count` components of a relative path ("meshes/collision/link0.stl").
std::string trailing_parts(const std::string& relative, int count) {
  std::size_t at = relative.size();
  for (int k = 0; k < count && at != std::string::npos && at > 0; ++k)
    at = relative.rfind('/', at - 1);
  return at == std::string::npos ? relative : relative.substr(at + 1);
}

constexpr std::size_t kMaxDirsShown = 8;

// Each directory may hold packages (DIR/NAME/rel), be the package itself (DIR/rel, its name
// NAME or not), or hold the files under a trailing part of rel: a model directory copied out
// of its package keeps "meshes/collision/link0.stl" but not "robots/panda_description/". The
// longest trailing part wins, and at least the file and its directory must match (a lone file
// name could be any link's mesh).
std::optional<fs::path> find_in_package_dirs(const std::vector<fs::path>& dirs,
                                             const std::string& package,
                                             const std::string& relative) {
  for (const fs::path& dir : dirs) {
    if (exists_file(dir / package / relative)) return dir / package / relative;
    if (exists_file(dir / relative)) return dir / relative;
  }
  for (const fs::path& dir : dirs) {
    for (std::size_t slash = relative.find('/'); slash != std::string::npos;
         slash = relative.find('/', slash + 1)) {
      const std::string tail = relative.substr(slash + 1);
      if (tail.find('/') == std::string::npos) break;
      if (exists_file(dir / tail)) return dir / tail;
    }
  }
  return std::nullopt;
}

}  // namespace

std::vector<std::string_view> split_ws(std::string_view text) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && is_space(text[i])) ++i;
    const std::size_t start = i;
    while (i < text.size() && !is_space(text[i])) ++i;
    if (i > start) out.push_back(text.substr(start, i - start));
  }
  return out;
}

std::optional<fs::path> resolve_mesh_path(const std::string& uri, const fs::path& base_dir,
                                          const LoadOptions& options, std::string* why) {
  constexpr std::string_view kPackage = "package://";
  constexpr std::string_view kFile = "file://";
  const std::string_view u(uri);
  if (u.substr(0, kPackage.size()) == kPackage) {
    const std::string_view rest = u.substr(kPackage.size());
    const auto slash = rest.find('/');
    if (slash == std::string_view::npos || slash == 0) {
      if (why) *why = "expected package://NAME/path, got '" + uri + "'";
      return std::nullopt;
    }
    const std::string package(rest.substr(0, slash));
    const std::string relative(rest.substr(slash + 1));
    std::vector<fs::path> dirs = options.package_path;
    if (options.use_ros_package_path) {
      if (const char* env = std::getenv("ROS_PACKAGE_PATH")) {
        for (std::string_view e(env); !e.empty();) {
          const auto colon = e.find(':');
          const std::string_view dir = e.substr(0, colon);
          if (!dir.empty()) dirs.emplace_back(std::string(dir));
          if (colon == std::string_view::npos) break;
          e.remove_prefix(colon + 1);
        }
      }
    }
    if (const auto found = find_in_package_dirs(dirs, package, relative)) return found;
    if (why) {
      std::string searched;
      for (std::size_t i = 0; i < dirs.size() && i < kMaxDirsShown; ++i)
        searched += (i == 0 ? "'" : ", '") + dirs[i].string() + "'";
      if (dirs.size() > kMaxDirsShown)
        searched += " and " + std::to_string(dirs.size() - kMaxDirsShown) + " more";
      *why = "cannot resolve '" + uri + "': no file '" + relative + "' of package '" + package +
             "' (nor a trailing part of that path, such as '" + trailing_parts(relative, 2) +
             "') in the directories searched: " + (dirs.empty() ? std::string("none") : searched) +
             (options.use_ros_package_path ? " (--package-path DIR, then ROS_PACKAGE_PATH)"
                                           : " (--package-path DIR)") +
             "; give --package-path DIR with DIR the directory holding the package '" + package +
             "', or the package's own directory";
    }
    return std::nullopt;
  }
  fs::path p;
  if (u.substr(0, kFile.size()) == kFile) {
    p = fs::path(std::string(u.substr(kFile.size())));
  } else if (const auto scheme = u.find("://"); scheme != std::string_view::npos) {
    if (why)
      *why = "unsupported URI scheme in '" + uri + "' (expected package://, file:// or a path)";
    return std::nullopt;
  } else {
    p = fs::path(uri);
    if (p.is_relative()) p = base_dir / p;
  }
  std::error_code ec;
  if (!fs::exists(p, ec)) {
    if (why) *why = "mesh file '" + p.string() + "' not found (from '" + uri + "')";
    return std::nullopt;
  }
  try {
    // There, but a directory, a FIFO, a device or too large: say which.
    check_input_file(p, "mesh", kMaxMeshFileBytes);
  } catch (const Error& e) {
    if (why) *why = std::string(e.what()) + " (from '" + uri + "')";
    return std::nullopt;
  }
  return p;
}

GeometryModel build_geometry(const Model& model, const std::vector<ShapeSpec>& shapes,
                             const fs::path& base_dir, const LoadOptions& options) {
  GeometryModel geometry;
  geometry.body_shapes.resize(static_cast<std::size_t>(model.num_bodies()));
  for (const ShapeSpec& spec : shapes) {
    CollisionShape shape = shape_on_frame(model, spec.shape, spec.frame, spec.source);
    if (shape.type == ShapeType::kMesh) {
      std::string why;
      const auto path = resolve_mesh_path(spec.mesh_uri, base_dir, options, &why);
      if (options.load_meshes) {
        if (!path) throw Error(spec.source + ": attribute 'filename': " + why);
        try {
          shape.mesh = load_mesh(*path, shape.scale);
        } catch (const Error& e) {
          throw Error(spec.source + ": " + e.what());
        }
      } else {
        // Kept without triangles, so tools can still list it.
        auto mesh = std::make_shared<TriangleMesh>();
        mesh->path = path ? path->string() : spec.mesh_uri;
        mesh->vertices.resize(3, 0);
        mesh->triangles.resize(3, 0);
        shape.mesh = std::move(mesh);
      }
    }
    geometry.add(std::move(shape));
  }
  return geometry;
}

}  // namespace extwrench::io_detail
