// DH table in YAML (yaml-cpp) -> ModelBuilder specs + collision shapes. The format, with every
// key and unit, is in docs/model.md. Strict: unknown keys, non-numbers, missing required keys
// are errors naming file:line and the key.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <map>

#include "detail/yaml_reader.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/model_builder.hpp"
#include "loader_detail.hpp"

namespace extwrench {

namespace {

namespace fs = std::filesystem;
using io_detail::YamlReader;

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

constexpr double kInf = std::numeric_limits<double>::infinity();

class DhParser {
 public:
  DhParser(std::string file, fs::path base_dir)
      : rd_(std::move(file)), base_dir_(std::move(base_dir)) {}

  RobotDescription parse(const YAML::Node& root, const LoadOptions& options) {
    rd_.only_keys(root, "", {"name", "convention", "gravity", "base", "joints", "frames"});
    ModelBuilder builder;
    builder.set_name(root["name"] ? rd_.string(root["name"], "name")
                                  : fs::path(rd_.file()).stem().string());
    if (!root["convention"])
      rd_.fail(root, "convention", "missing (required: standard or modified)");
    modified_ = rd_.one_of(root["convention"], "convention", {"standard", "modified"}) == 1;
    if (root["gravity"]) builder.set_gravity(rd_.vector3(root["gravity"], "gravity"));
    if (options.gravity) builder.set_gravity(*options.gravity);

    // Link 0.
    if (!root["base"]) rd_.fail(root, "base", "missing (required: link 0)");
    const YAML::Node base = root["base"];
    rd_.only_keys(base, "base", {"name", "mass", "com", "inertia", "collision"});
    parent_ = base["name"] ? rd_.string(base["name"], "base.name") : std::string("link0");
    builder.add_link(link_spec(base, "base", parent_, Pose::identity()));
    parse_collisions(base, "base", parent_, Pose::identity());
    dh_placement_[parent_] = Pose::identity();

    const YAML::Node joints = rd_.required(root, "", "joints");
    if (!joints.IsSequence() || joints.size() == 0)
      rd_.fail(joints, "joints", "expected a non-empty list of joints");
    for (std::size_t i = 0; i < joints.size(); ++i)
      parse_joint(joints[i], YamlReader::item("joints", i), builder);
    if (const YAML::Node frames = root["frames"]) parse_frames(frames, builder);

    RobotDescription r;
    lock_joints(options, builder);
    r.model = builder.build();
    r.geometry = io_detail::build_geometry(r.model, shapes_, base_dir_, options);
    return r;
  }

 private:
  /// Source of ModelBuilder messages: "file:line".
  std::string at(const YAML::Node& n) const { return rd_.where(n); }

  // A joint and its link; P_prev_ is X_{body, DH frame} of the previous link: identity unless it
  // is a standard-DH link with a != 0.
  void parse_joint(const YAML::Node& j, const std::string& path, ModelBuilder& builder) {
    rd_.only_keys(j, path,
                  {"name", "type", "a", "alpha", "d", "theta", "lower", "upper", "velocity",
                   "effort", "damping", "friction", "armature", "link"});
    JointSpec js;
    js.source = at(j);
    js.name = rd_.string(rd_.required(j, path, "name"), path + ".name");
    const bool revolute =
        rd_.one_of(rd_.required(j, path, "type"), path + ".type", {"revolute", "prismatic"}) == 0;
    js.type = revolute ? JointSpecType::kRevolute : JointSpecType::kPrismatic;
    const double a = number(j, "a", path);
    const double alpha = angle(j, "alpha", path);
    const double d = number(j, "d", path);
    const double theta = angle(j, "theta", path);
    js.lower = revolute ? angle(j, "lower", path, -kInf) : number(j, "lower", path, -kInf);
    js.upper = revolute ? angle(j, "upper", path, kInf) : number(j, "upper", path, kInf);
    if (js.lower > js.upper) rd_.fail(j["lower"], path + ".lower", "lower > upper");
    js.velocity_limit = number(j, "velocity", path, kInf);
    js.effort_limit = number(j, "effort", path, kInf);
    js.damping = number(j, "damping", path, 0.0);
    js.friction = number(j, "friction", path, 0.0);
    js.armature = number(j, "armature", path, 0.0);
    if (js.armature < 0.0) rd_.fail(j["armature"], path + ".armature", "expected a number >= 0");
    const Pose P = place(js, a, alpha, d, theta);  // X_{body i, DH frame i}
    js.parent = parent_;

    const YAML::Node link = rd_.required(j, path, "link");
    const std::string lpath = path + ".link";
    rd_.only_keys(link, lpath, {"name", "mass", "com", "inertia", "collision", "dh_frame"});
    js.child = rd_.string(rd_.required(link, lpath, "name"), lpath + ".name");
    builder.add_link(link_spec(link, lpath, js.child, P));
    builder.add_joint(js);
    parse_collisions(link, lpath, js.child, P);
    dh_placement_[js.child] = P;
    const bool separate_dh_frame = !modified_ && a != 0.0;
    if (link["dh_frame"] && !separate_dh_frame) {
      rd_.fail(
          link["dh_frame"], lpath + ".dh_frame",
          "only allowed for standard DH with a != 0 (otherwise the link frame is the DH frame)");
    }
    if (separate_dh_frame) {
      FrameSpec f;
      f.name =
          link["dh_frame"] ? rd_.string(link["dh_frame"], lpath + ".dh_frame") : js.child + "_dh";
      f.link = js.child;
      f.placement = P;
      f.source = at(link);
      builder.add_frame(f);
    }
    parent_ = js.child;
    P_prev_ = P;
  }

  // Sets js.origin and js.axis; returns X_{body i, DH frame i}. The body frame is the joint frame
  // after the motion (X_{parent,i}(q) = placement Rot(axis, q)).
  Pose place(JointSpec& js, double a, double alpha, double d, double theta) const {
    if (modified_) {
      // Craig: frame_i = frame_{i-1} Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta + q) Tz(d): body = DH
      // frame.
      js.origin = P_prev_ * rot_x(alpha) * trans(a, 0, 0) * rot_z(theta) * trans(0, 0, d);
      js.axis = Vector3::UnitZ();
      return Pose::identity();
    }
    if (a == 0.0) {
      // Standard, a = 0: frame_i = frame_{i-1} Rz(theta + q) Tz(d) Rx(alpha) = [Rz(theta) Tz(d)
      // Rx(alpha)] Rot(axis, q) with axis = Rx(alpha)^T z = (0, sin alpha, cos alpha): the body
      // frame is the DH frame.
      js.origin = P_prev_ * rot_z(theta) * trans(0, 0, d) * rot_x(alpha);
      js.axis = Vector3(0.0, std::sin(alpha), std::cos(alpha));
      return Pose::identity();
    }
    // Standard, a != 0: the DH origin is off the joint axis, so the body frame stops after
    // Rz(theta + q) Tz(d) and DH frame i = body * Tx(a) Rx(alpha) becomes a named Frame.
    js.origin = P_prev_ * rot_z(theta) * trans(0, 0, d);
    js.axis = Vector3::UnitZ();
    return trans(a, 0, 0) * rot_x(alpha);
  }

  void parse_frames(const YAML::Node& frames, ModelBuilder& builder) const {
    if (!frames.IsSequence()) rd_.fail(frames, "frames", "expected a list of frames");
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const YAML::Node f = frames[i];
      const std::string path = YamlReader::item("frames", i);
      rd_.only_keys(f, path, {"name", "link", "xyz", "rpy"});
      FrameSpec fs;
      fs.name = rd_.string(rd_.required(f, path, "name"), path + ".name");
      fs.link = rd_.string(rd_.required(f, path, "link"), path + ".link");
      fs.source = at(f);
      const auto dh = dh_placement_.find(fs.link);
      if (dh == dh_placement_.end())
        rd_.fail(f["link"], path + ".link", "no link named '" + fs.link + "'");
      // Given in the link's DH frame.
      fs.placement = dh->second * rd_.xyz_rpy(f, path, true);
      builder.add_frame(fs);
    }
  }

  // map[key] as a number (an angle: pi expressions allowed); `fallback` when absent, else
  // required.
  double number(const YAML::Node& map, const char* key, const std::string& path,
                std::optional<double> fallback = std::nullopt) const {
    if (!map[key] && fallback) return *fallback;
    return rd_.number(rd_.required(map, path, key), YamlReader::key(path, key));
  }
  double angle(const YAML::Node& map, const char* key, const std::string& path,
               std::optional<double> fallback = std::nullopt) const {
    if (!map[key] && fallback) return *fallback;
    return rd_.angle(rd_.required(map, path, key), YamlReader::key(path, key));
  }

  // [ixx, ixy, ixz, iyy, iyz, izz] or a 3x3 list of rows.
  Matrix3 inertia(const YAML::Node& n, const std::string& p) const {
    Matrix3 I;
    if (n.IsSequence() && n.size() == 6) {
      double v[6];
      for (std::size_t i = 0; i < 6; ++i) v[i] = rd_.number(n[i], YamlReader::item(p, i));
      I << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
      return I;
    }
    if (n.IsSequence() && n.size() == 3) {
      for (std::size_t r = 0; r < 3; ++r) {
        const std::string row = YamlReader::item(p, r);
        const Vector3 v = rd_.vector3(n[r], row);
        I.row(static_cast<Eigen::Index>(r)) = v.transpose();
      }
      return I;
    }
    rd_.fail(n, p, "expected 6 numbers [ixx, ixy, ixz, iyy, iyz, izz] or a 3x3 matrix");
  }

  // Mass properties given in the DH frame (X_{body, DH} = P), returned in the body frame.
  LinkSpec link_spec(const YAML::Node& map, const std::string& path, const std::string& name,
                     const Pose& P) const {
    LinkSpec l;
    l.name = name;
    l.source = at(map);
    Inertia in;
    in.mass = rd_.number_in(rd_.required(map, path, "mass"), path + ".mass",
                            io_detail::non_negative(">= 0 [kg]"));
    in.com = rd_.vector3_or(map, path, "com", Vector3::Zero());
    if (map["inertia"]) {
      in.inertia_com = inertia(map["inertia"], path + ".inertia");
      l.inertia_source = at(map["inertia"]) + ": " + path + ".inertia";
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
    if (!list.IsSequence()) rd_.fail(list, path + ".collision", "expected a list of shapes");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YAML::Node c = list[i];
      const std::string p = YamlReader::item(path + ".collision", i);
      if (!c.IsMap()) rd_.fail(c, p, "expected a mapping");
      io_detail::ShapeSpec spec;
      spec.frame = link;
      spec.source = at(c) + ": " + p + " of link '" + link + "'";
      read_shape(c, p, spec);
      // Declared in the DH frame: X_{body, shape} = P X_{DH, shape}.
      spec.shape.placement = P * rd_.xyz_rpy(c, p, true);
      shapes_.push_back(std::move(spec));
    }
  }

  void read_shape(const YAML::Node& c, const std::string& p, io_detail::ShapeSpec& spec) const {
    CollisionShape& s = spec.shape;
    const io_detail::Range length = io_detail::positive("> 0 [m]");
    const auto positive = [&](const char* key) {
      return rd_.number_in(rd_.required(c, p, key), YamlReader::key(p, key), length);
    };
    switch (rd_.one_of(rd_.required(c, p, "type"), p + ".type",
                       {"sphere", "box", "cylinder", "capsule", "mesh"})) {
      case 0:
        rd_.only_keys(c, p, {"type", "radius", "xyz", "rpy"});
        s.type = ShapeType::kSphere;
        s.radius = positive("radius");
        break;
      case 1:
        rd_.only_keys(c, p, {"type", "size", "xyz", "rpy"});
        s.type = ShapeType::kBox;
        s.size = rd_.vector3(rd_.required(c, p, "size"), p + ".size");
        if (!(s.size.minCoeff() > 0.0)) rd_.fail(c["size"], p + ".size", "expected values > 0 [m]");
        break;
      case 2:
      case 3:
        rd_.only_keys(c, p, {"type", "radius", "length", "xyz", "rpy"});
        s.type = c["type"].Scalar() == "cylinder" ? ShapeType::kCylinder : ShapeType::kCapsule;
        s.radius = positive("radius");
        s.length = s.type == ShapeType::kCylinder
                       ? positive("length")
                       : rd_.number_in(rd_.required(c, p, "length"), p + ".length",
                                       io_detail::non_negative(">= 0 [m]"));
        break;
      default:
        rd_.only_keys(c, p, {"type", "filename", "scale", "xyz", "rpy"});
        s.type = ShapeType::kMesh;
        spec.mesh_uri = rd_.string(rd_.required(c, p, "filename"), p + ".filename");
        s.scale = rd_.vector3_or(c, p, "scale", Vector3::Ones());
        break;
    }
  }

  YamlReader rd_;
  fs::path base_dir_;
  bool modified_ = false;
  std::string parent_;              // the link the next joint hangs from
  Pose P_prev_ = Pose::identity();  // X_{body, DH frame} of that link
  std::vector<io_detail::ShapeSpec> shapes_;
  std::map<std::string, Pose> dh_placement_;  // link -> X_{body, DH frame}
};

}  // namespace

RobotDescription load_dh_yaml(const fs::path& path, const LoadOptions& options) {
  const YAML::Node root = io_detail::load_yaml_file(path, "robot");
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
