// DH table in YAML (yaml-cpp) -> ModelBuilder specs + collision shapes. The format, with every
// key and unit, is in docs/model.md. Strict: unknown keys, non-numbers, missing required keys
// are errors naming file:line and the key.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "extwrench/core/error.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/model_builder.hpp"
#include "loader_detail.hpp"

namespace extwrench {

namespace {

namespace fs = std::filesystem;

Pose rot_x(double a) {
  Pose x;
  x.rotation = Eigen::AngleAxisd(a, Vector3::UnitX()).toRotationMatrix();
  return x;
}
Pose rot_z(double a) {
  Pose x;
  x.rotation = Eigen::AngleAxisd(a, Vector3::UnitZ()).toRotationMatrix();
  return x;
}
Pose trans(double x, double y, double z) {
  Pose p;
  p.translation = Vector3(x, y, z);
  return p;
}

// "1.5", "pi", "-pi/2", "2*pi/3", "0.5*pi": angles may be written with pi.
std::optional<double> parse_angle(std::string_view text) {
  if (const auto d = io_detail::parse_double(text)) return d;
  const auto tokens = io_detail::split_ws(text);
  if (tokens.size() != 1) return std::nullopt;
  std::string_view s = tokens[0];
  double sign = 1.0;
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) {
    sign = s.front() == '-' ? -1.0 : 1.0;
    s.remove_prefix(1);
  }
  const auto pos = s.find("pi");
  if (pos == std::string_view::npos) return std::nullopt;
  double v = std::numbers::pi;
  const std::string_view before = s.substr(0, pos);
  const std::string_view after = s.substr(pos + 2);
  if (!before.empty()) {
    if (before.back() != '*') return std::nullopt;
    const auto f = io_detail::parse_double(before.substr(0, before.size() - 1));
    if (!f || before.front() == '-' || before.front() == '+') return std::nullopt;
    v *= *f;
  }
  if (!after.empty()) {
    if (after.front() != '/') return std::nullopt;
    const auto f = io_detail::parse_double(after.substr(1));
    if (!f || *f == 0.0 || after[1] == '-' || after[1] == '+') return std::nullopt;
    v /= *f;
  }
  return sign * v;
}

class DhParser {
 public:
  DhParser(std::string file, fs::path base_dir)
      : file_(std::move(file)), base_dir_(std::move(base_dir)) {}

  RobotDescription parse(const YAML::Node& root, const LoadOptions& options) {
    expect_map(root, "(document)", root);
    check_keys(root, "", {"name", "convention", "gravity", "base", "joints", "frames"});
    ModelBuilder builder;
    builder.set_name(root["name"] ? scalar(root["name"], "name") : fs::path(file_).stem().string());
    if (!root["convention"]) fail(root, "convention", "missing (required: standard or modified)");
    const std::string convention = scalar(root["convention"], "convention");
    bool modified = false;
    if (convention == "modified") {
      modified = true;
    } else if (convention != "standard") {
      fail(root["convention"], "convention",
           "expected 'standard' or 'modified', got '" + convention + "'");
    }
    if (root["gravity"]) builder.set_gravity(vec3(root, "gravity", "", std::nullopt));
    if (options.gravity) builder.set_gravity(*options.gravity);

    // Link 0.
    if (!root["base"]) fail(root, "base", "missing (required: link 0)");
    const YAML::Node base = root["base"];
    expect_map(base, "base", base);
    check_keys(base, "base", {"name", "mass", "com", "inertia", "collision"});
    std::string parent = base["name"] ? scalar(base["name"], "base.name") : std::string("link0");
    builder.add_link(link_spec(base, "base", parent, Pose::identity()));
    parse_collisions(base, "base", parent, Pose::identity());
    dh_placement_[parent] = Pose::identity();

    if (!root["joints"]) fail(root, "joints", "missing (required)");
    const YAML::Node joints = root["joints"];
    if (!joints.IsSequence() || joints.size() == 0)
      fail(joints, "joints", "expected a non-empty list of joints");
    // P = X_{body, DH frame} of the previous link: identity unless it is a standard-DH link with a
    // != 0.
    Pose P_prev = Pose::identity();
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const YAML::Node j = joints[i];
      const std::string path = "joints[" + std::to_string(i) + "]";
      expect_map(j, path, j);
      check_keys(j, path,
                 {"name", "type", "a", "alpha", "d", "theta", "lower", "upper", "velocity",
                  "effort", "damping", "friction", "link"});
      JointSpec js;
      js.source = at(j);
      js.name = required_scalar(j, "name", path);
      const std::string type = required_scalar(j, "type", path);
      if (type == "revolute") {
        js.type = JointSpecType::kRevolute;
      } else if (type == "prismatic") {
        js.type = JointSpecType::kPrismatic;
      } else {
        fail(j["type"], path + ".type", "expected 'revolute' or 'prismatic', got '" + type + "'");
      }
      const bool revolute = js.type == JointSpecType::kRevolute;
      const double a = number(j, "a", path, std::nullopt, false);
      const double alpha = number(j, "alpha", path, std::nullopt, true);
      const double d = number(j, "d", path, std::nullopt, false);
      const double theta = number(j, "theta", path, std::nullopt, true);
      js.lower = number(j, "lower", path, -std::numeric_limits<double>::infinity(), revolute);
      js.upper = number(j, "upper", path, std::numeric_limits<double>::infinity(), revolute);
      if (js.lower > js.upper) fail(j["lower"], path + ".lower", "lower > upper");
      js.velocity_limit =
          number(j, "velocity", path, std::numeric_limits<double>::infinity(), false);
      js.effort_limit = number(j, "effort", path, std::numeric_limits<double>::infinity(), false);
      js.damping = number(j, "damping", path, 0.0, false);
      js.friction = number(j, "friction", path, 0.0, false);

      // The body frame is the joint frame after the motion (X_{parent,i}(q) = placement Rot(axis,
      // q)).
      Pose P;  // X_{body i, DH frame i}
      if (modified) {
        // Craig: frame_i = frame_{i-1} Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta + q) Tz(d): body = DH
        // frame.
        js.origin = P_prev * rot_x(alpha) * trans(a, 0, 0) * rot_z(theta) * trans(0, 0, d);
        js.axis = Vector3::UnitZ();
      } else if (a == 0.0) {
        // Standard, a = 0: frame_i = frame_{i-1} Rz(theta + q) Tz(d) Rx(alpha) = [Rz(theta) Tz(d)
        // Rx(alpha)] Rot(axis, q) with axis = Rx(alpha)^T z = (0, sin alpha, cos alpha): the body
        // frame is the DH frame.
        js.origin = P_prev * rot_z(theta) * trans(0, 0, d) * rot_x(alpha);
        js.axis = Vector3(0.0, std::sin(alpha), std::cos(alpha));
      } else {
        // Standard, a != 0: the DH origin is off the joint axis, so the body frame stops after
        // Rz(theta + q) Tz(d) and DH frame i = body * Tx(a) Rx(alpha) becomes a named Frame.
        js.origin = P_prev * rot_z(theta) * trans(0, 0, d);
        js.axis = Vector3::UnitZ();
        P = trans(a, 0, 0) * rot_x(alpha);
      }
      js.parent = parent;

      if (!j["link"]) fail(j, path + ".link", "missing (required)");
      const YAML::Node link = j["link"];
      const std::string lpath = path + ".link";
      expect_map(link, lpath, link);
      check_keys(link, lpath, {"name", "mass", "com", "inertia", "collision", "dh_frame"});
      js.child = required_scalar(link, "name", lpath);
      builder.add_link(link_spec(link, lpath, js.child, P));
      builder.add_joint(js);
      parse_collisions(link, lpath, js.child, P);
      dh_placement_[js.child] = P;
      const bool separate_dh_frame = !modified && a != 0.0;
      if (link["dh_frame"] && !separate_dh_frame) {
        fail(link["dh_frame"], lpath + ".dh_frame",
             "only allowed for standard DH with a != 0 (otherwise the link frame is the DH frame)");
      }
      if (separate_dh_frame) {
        FrameSpec f;
        f.name =
            link["dh_frame"] ? scalar(link["dh_frame"], lpath + ".dh_frame") : js.child + "_dh";
        f.link = js.child;
        f.placement = P;
        f.source = at(link);
        builder.add_frame(f);
      }
      parent = js.child;
      P_prev = P;
    }

    if (const YAML::Node frames = root["frames"]) {
      if (!frames.IsSequence()) fail(frames, "frames", "expected a list of frames");
      for (std::size_t i = 0; i < frames.size(); ++i) {
        const YAML::Node f = frames[i];
        const std::string path = "frames[" + std::to_string(i) + "]";
        expect_map(f, path, f);
        check_keys(f, path, {"name", "link", "xyz", "rpy"});
        FrameSpec fs;
        fs.name = required_scalar(f, "name", path);
        fs.link = required_scalar(f, "link", path);
        fs.source = at(f);
        const auto dh = dh_placement_.find(fs.link);
        if (dh == dh_placement_.end())
          fail(f["link"], path + ".link", "no link named '" + fs.link + "'");
        // Given in the link's DH frame.
        fs.placement = dh->second * pose(f, path);
        builder.add_frame(fs);
      }
    }

    RobotDescription r;
    r.model = builder.build();
    r.geometry = io_detail::build_geometry(r.model, shapes_, base_dir_, options);
    return r;
  }

 private:
  std::string at(const YAML::Node& n) const {
    const auto m = n.Mark();
    return file_ + ":" + std::to_string(m.is_null() ? 0 : m.line + 1);
  }
  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& key,
                         const std::string& what) const {
    throw Error(at(n) + ": key '" + key + "': " + what);
  }
  void expect_map(const YAML::Node& n, const std::string& path, const YAML::Node& where) const {
    if (!n.IsMap()) fail(where, path, "expected a mapping");
  }
  void check_keys(const YAML::Node& map, const std::string& path,
                  std::initializer_list<const char*> allowed) const {
    const std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      if (!ok.count(k)) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(kv.first, join(path, k), "unknown key (allowed: " + list + ")");
      }
    }
  }
  std::string scalar(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected a single value");
    return n.Scalar();
  }
  std::string required_scalar(const YAML::Node& map, const char* key,
                              const std::string& path) const {
    if (!map[key]) fail(map, join(path, key), "missing (required)");
    const std::string s = scalar(map[key], join(path, key));
    if (s.empty()) fail(map[key], join(path, key), "must not be empty");
    return s;
  }
  double to_number(const YAML::Node& n, const std::string& path, bool angle) const {
    const std::string s = scalar(n, path);
    const auto v = angle ? parse_angle(s) : io_detail::parse_double(s);
    if (!v)
      fail(n, path,
           std::string("expected a number") + (angle ? " (or pi expression)" : "") + ", got '" + s +
               "'");
    return *v;
  }
  double number(const YAML::Node& map, const char* key, const std::string& path,
                std::optional<double> fallback, bool angle) const {
    const YAML::Node n = map[key];
    if (!n) {
      if (fallback) return *fallback;
      fail(map, join(path, key), "missing (required)");
    }
    return to_number(n, join(path, key), angle);
  }
  Vector3 vec3(const YAML::Node& map, const char* key, const std::string& path,
               std::optional<Vector3> fallback, bool angle = false) const {
    const YAML::Node n = map[key];
    const std::string p = join(path, key);
    if (!n) {
      if (fallback) return *fallback;
      fail(map, p, "missing (required)");
    }
    if (!n.IsSequence() || n.size() != 3) fail(n, p, "expected a list of 3 numbers");
    Vector3 v;
    for (std::size_t i = 0; i < 3; ++i)
      v[static_cast<Eigen::Index>(i)] = to_number(n[i], p + "[" + std::to_string(i) + "]", angle);
    return v;
  }
  Pose pose(const YAML::Node& map, const std::string& path) const {
    return Pose::from_xyz_rpy(vec3(map, "xyz", path, Vector3::Zero()),
                              vec3(map, "rpy", path, Vector3::Zero(), true));
  }
  // [ixx, ixy, ixz, iyy, iyz, izz] or a 3x3 list of rows.
  Matrix3 inertia(const YAML::Node& n, const std::string& p) const {
    Matrix3 I;
    if (n.IsSequence() && n.size() == 6) {
      double v[6];
      for (std::size_t i = 0; i < 6; ++i)
        v[i] = to_number(n[i], p + "[" + std::to_string(i) + "]", false);
      I << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
      return I;
    }
    if (n.IsSequence() && n.size() == 3) {
      for (std::size_t r = 0; r < 3; ++r) {
        if (!n[r].IsSequence() || n[r].size() != 3)
          fail(n[r], p + "[" + std::to_string(r) + "]", "expected a row of 3 numbers");
        for (std::size_t c = 0; c < 3; ++c) {
          I(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = to_number(
              n[r][c], p + "[" + std::to_string(r) + "][" + std::to_string(c) + "]", false);
        }
      }
      return I;
    }
    fail(n, p, "expected 6 numbers [ixx, ixy, ixz, iyy, iyz, izz] or a 3x3 matrix");
  }

  // Mass properties given in the DH frame (X_{body, DH} = P), returned in the body frame.
  LinkSpec link_spec(const YAML::Node& map, const std::string& path, const std::string& name,
                     const Pose& P) const {
    LinkSpec l;
    l.name = name;
    l.source = at(map);
    Inertia in;
    in.mass = number(map, "mass", path, std::nullopt, false);
    if (in.mass < 0.0)
      fail(map["mass"], join(path, "mass"),
           "must not be negative, got '" + map["mass"].Scalar() + "'");
    in.com = vec3(map, "com", path, Vector3::Zero());
    if (map["inertia"]) {
      in.inertia_com = inertia(map["inertia"], path + ".inertia");
      l.inertia_source = at(map["inertia"]) + ": key '" + path + ".inertia'";
    }
    // Check before the rotation hides an asymmetric or non-physical input.
    validate_inertia(
        in, (l.inertia_source.empty() ? l.source : l.inertia_source) + ": link '" + name + "'");
    l.inertia = in.transformed(P);
    return l;
  }

  void parse_collisions(const YAML::Node& map, const std::string& path, const std::string& link,
                        const Pose& P) {
    const YAML::Node list = map["collision"];
    if (!list) return;
    if (!list.IsSequence()) fail(list, path + ".collision", "expected a list of shapes");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node c = list[i];
      const std::string p = path + ".collision[" + std::to_string(i) + "]";
      expect_map(c, p, c);
      io_detail::ShapeSpec spec;
      spec.frame = link;
      spec.source = at(c) + ": key '" + p + "' of link '" + link + "'";
      CollisionShape& s = spec.shape;
      const std::string type = required_scalar(c, "type", p);
      auto positive = [&](const char* key) {
        const double v = number(c, key, p, std::nullopt, false);
        if (!(v > 0.0)) fail(c[key], p + "." + key, "must be positive");
        return v;
      };
      if (type == "sphere") {
        check_keys(c, p, {"type", "radius", "xyz", "rpy"});
        s.type = ShapeType::kSphere;
        s.radius = positive("radius");
      } else if (type == "box") {
        check_keys(c, p, {"type", "size", "xyz", "rpy"});
        s.type = ShapeType::kBox;
        s.size = vec3(c, "size", p, std::nullopt);
        if (!(s.size.minCoeff() > 0.0)) fail(c["size"], p + ".size", "must be positive");
      } else if (type == "cylinder" || type == "capsule") {
        check_keys(c, p, {"type", "radius", "length", "xyz", "rpy"});
        s.type = type == "cylinder" ? ShapeType::kCylinder : ShapeType::kCapsule;
        s.radius = positive("radius");
        s.length = number(c, "length", p, std::nullopt, false);
        if (s.length < 0.0 || (s.type == ShapeType::kCylinder && s.length == 0.0))
          fail(c["length"], p + ".length", "must be positive");
      } else if (type == "mesh") {
        check_keys(c, p, {"type", "filename", "scale", "xyz", "rpy"});
        s.type = ShapeType::kMesh;
        spec.mesh_uri = required_scalar(c, "filename", p);
        s.scale = vec3(c, "scale", p, Vector3::Ones());
      } else {
        fail(c["type"], p + ".type",
             "unknown shape '" + type + "' (expected sphere, box, cylinder, capsule or mesh)");
      }
      // Declared in the DH frame: X_{body, shape} = P X_{DH, shape}.
      s.placement = P * pose(c, p);
      shapes_.push_back(std::move(spec));
    }
  }

  std::string file_;
  fs::path base_dir_;
  std::vector<io_detail::ShapeSpec> shapes_;
  std::map<std::string, Pose> dh_placement_;  // link -> X_{body, DH frame}
};

}  // namespace

RobotDescription load_dh_yaml(const fs::path& path, const LoadOptions& options) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::BadFile&) {
    throw Error(path.string() + ": cannot open file");
  } catch (const YAML::ParserException& e) {
    throw Error(path.string() + ":" + std::to_string(e.mark.line + 1) +
                ": not valid YAML: " + e.msg);
  }
  DhParser parser(path.string(), path.parent_path().empty() ? fs::path(".") : path.parent_path());
  RobotDescription r;
  try {
    r = parser.parse(root, options);
  } catch (const YAML::Exception& e) {
    // Type conversions inside yaml-cpp (rare: keys that are not scalars).
    throw Error(path.string() + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  r.source = path;
  return r;
}

}  // namespace extwrench
