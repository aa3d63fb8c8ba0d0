// URDF -> ModelBuilder specs + collision shapes (tinyxml2). Strict: every number we read must be
// a whole finite number, every required attribute present; errors name file:line, element,
// attribute and the offending text. The subset and the <capsule> extension: docs/model.md.
#include <tinyxml2.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/nearest_name.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/model_builder.hpp"
#include "loader_detail.hpp"

namespace extwrench {

namespace {

namespace fs = std::filesystem;

// Attributes are finite numbers, spaces around them allowed (urdfdom would read "abc" as 0).
constexpr NumberRules kUrdfNumber{.trim_space = true};
using tinyxml2::XMLElement;

// Text from the file as messages show it: control and non-ASCII bytes as \xNN, cut at 60.
std::string shown(std::string_view text) {
  constexpr std::size_t kMax = 60;
  std::string out;
  for (const char c : text.substr(0, kMax)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    }
  }
  return text.size() > kMax ? out + "..." : out;
}

constexpr const char* kEmpty = ": the file is empty (or holds only white space and comments)";

class UrdfParser {
 public:
  explicit UrdfParser(std::string file) : file_(std::move(file)) {}

  RobotDescription parse(const std::string& xml, const fs::path& base_dir,
                         const LoadOptions& options) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
      if (doc.ErrorID() == tinyxml2::XML_ERROR_EMPTY_DOCUMENT) throw Error(file_ + kEmpty);
      throw Error(file_ + ":" + std::to_string(doc.ErrorLineNum()) +
                  ": not well-formed XML: " + (doc.ErrorStr() ? doc.ErrorStr() : "unknown error"));
    }
    const XMLElement* robot = doc.RootElement();
    if (robot == nullptr) throw Error(file_ + kEmpty);  // only a declaration or comments
    if (robot != nullptr && std::strcmp(robot->Name(), "mujoco") == 0) {
      throw Error(
          file_ + ":" + std::to_string(robot->GetLineNum()) +
          ": the root element is <mujoco>: an MJCF file. MJCF needs extwrench built with "
          "MuJoCo (libmujoco-dev, -DEXTWRENCH_BUILD_MUJOCO=ON) and read through "
          "load_robot in a program linked with extwrench::mujoco (the extwrench CLI and Python "
          "module are, when built with it)");
    }
    if (robot == nullptr || std::strcmp(robot->Name(), "robot") != 0) {
      // MuJoCo ignores the root's name in an <include>d file (the Menagerie-style <panda> of a
      // robot split over files), so a user may give us that part.
      throw Error(file_ + ":" + std::to_string(robot ? robot->GetLineNum() : 1) +
                  ": the root element must be <robot> (URDF) or <mujoco> (MJCF), got <" +
                  (robot ? robot->Name() : "") +
                  ">: if this is part of an MJCF model, which another file <include>s, load that "
                  "file");
    }
    ModelBuilder builder;
    if (const char* name = robot->Attribute("name")) builder.set_name(name);
    // A .urdf.xacro given as it is: its macros would be skipped as extensions, and the robot
    // they make (a gripper, a whole arm) silently left out.
    for (const XMLElement* e = robot->FirstChildElement(); e != nullptr;
         e = e->NextSiblingElement()) {
      if (std::strncmp(e->Name(), "xacro:", 6) == 0) {
        throw Error(where(e) + ": <" + shown(e->Name()) +
                    ">: a xacro macro, which a URDF cannot hold: expand the file first (ROS's "
                    "xacro: `xacro robot.urdf.xacro > robot.urdf`) and load the result");
      }
    }
    if (robot->FirstChildElement("link") == nullptr) {
      const char* name = robot->Attribute("name");
      throw Error(where(robot) + ": <robot" + (name ? " '" + shown(name) + "'" : std::string()) +
                  ">: no <link> elements (a robot needs at least one link)");
    }
    if (options.gravity) builder.set_gravity(*options.gravity);
    // Only direct children: <link> inside <gazebo> & co. are not links. Unknown elements
    // (<gazebo>, <transmission>, <material>, <mujoco>, ...) are extensions and ignored.
    for (const XMLElement* e = robot->FirstChildElement(); e != nullptr;
         e = e->NextSiblingElement()) {
      if (std::strcmp(e->Name(), "link") == 0) {
        builder.add_link(parse_link(e));
      } else if (std::strcmp(e->Name(), "joint") == 0) {
        builder.add_joint(parse_joint(e));
      }
    }
    check_mimics(robot, options);
    lock_joints(options, builder);
    RobotDescription robot_description;
    robot_description.model = builder.build();
    robot_description.geometry =
        io_detail::build_geometry(robot_description.model, shapes_, base_dir, options);
    return robot_description;
  }

 private:
  std::string where(const XMLElement* e) const {
    return file_ + ":" + std::to_string(e->GetLineNum());
  }
  // "file:line: <inertia> of link 'x'"
  std::string context(const XMLElement* e, const std::string& owner) const {
    return where(e) + ": <" + e->Name() + ">" + (owner.empty() ? "" : " of " + owner);
  }

  [[noreturn]] void fail(const XMLElement* e, const std::string& owner,
                         const std::string& what) const {
    throw Error(context(e, owner) + ": " + what);
  }

  // validate_inertia on the numbers as the file writes them (the model checks them again in the
  // link frame), so that the message can point at them: exported and Gazebo files often carry
  // placeholder products of inertia (0.01 beside moments of 0.002) that make a tensor
  // non-physical while its diagonal alone is fine.
  void check_inertia_as_written(const Inertia& in, const XMLElement* e,
                                const std::string& owner) const {
    try {
      validate_inertia(in, "");
    } catch (const Error& error) {
      std::string what = error.what();
      Inertia diagonal = in;
      diagonal.inertia_com = in.inertia_com.diagonal().asDiagonal();
      bool diagonal_physical = true;
      try {
        validate_inertia(diagonal, "");
      } catch (const Error&) {
        diagonal_physical = false;
      }
      if (diagonal_physical) {
        what += "; ixx, iyy, izz alone would be physical: are the products ixy, ixz, iyz (" +
                shown(e->Attribute("ixy")) + ", " + shown(e->Attribute("ixz")) + ", " +
                shown(e->Attribute("iyz")) + ") placeholders? (write 0 where unknown)";
      }
      fail(e, owner, what);
    }
  }

  const char* required(const XMLElement* e, const char* attr, const std::string& owner) const {
    const char* v = e->Attribute(attr);
    if (v == nullptr) fail(e, owner, std::string("attribute '") + attr + "': missing (required)");
    return v;
  }

  const XMLElement* required_child(const XMLElement* e, const char* name,
                                   const std::string& owner) const {
    const XMLElement* c = e->FirstChildElement(name);
    if (c == nullptr) fail(e, owner, std::string("missing element <") + name + ">");
    return c;
  }

  // A <mimic> joint follows its leader, which this model does not enforce: it stays a joint of
  // its own. Locking the leader alone then left the follower free (the Panda's second finger as
  // q8, met as a missing log column); the follower's value is known, so say it.
  void check_mimics(const XMLElement* robot, const LoadOptions& options) const {
    for (const XMLElement* e = robot->FirstChildElement("joint"); e != nullptr;
         e = e->NextSiblingElement("joint")) {
      const XMLElement* mimic = e->FirstChildElement("mimic");
      const char* follower = e->Attribute("name");
      if (mimic == nullptr || follower == nullptr) continue;
      const std::string owner = "joint '" + std::string(follower) + "'";
      const std::string leader = required(mimic, "joint", owner);
      const auto locked = options.locked_joints.find(leader);
      if (locked == options.locked_joints.end() || options.locked_joints.count(follower) != 0)
        continue;
      // A leader locked outside its limits is that error (the builder's), not advice to lock the
      // follower at a value derived from it (a review's finger at 0.5 of [0, 0.04]).
      if (outside_limits(robot, leader, locked->second)) continue;
      const double value = number(mimic, "multiplier", owner, 1.0) * locked->second +
                           number(mimic, "offset", owner, 0.0);
      char shown[32];  // as a user would type it (0.3, not 0.30000000000000004)
      std::snprintf(shown, sizeof shown, "%.12g", value);
      fail(mimic, owner,
           "follows joint '" + leader + "' (<mimic>), which is locked: lock it too, at " +
               std::string(shown) + " (--lock " + follower + "=" + shown + ")");
    }
  }

  // Whether `value` lies outside the <limit> of the joint named `name` (a joint without one, or
  // continuous, has none to lie outside of).
  bool outside_limits(const XMLElement* robot, const std::string& name, double value) const {
    for (const XMLElement* e = robot->FirstChildElement("joint"); e != nullptr;
         e = e->NextSiblingElement("joint")) {
      const char* joint = e->Attribute("name");
      if (joint == nullptr || name != joint) continue;
      const char* type = e->Attribute("type");
      const XMLElement* limit = e->FirstChildElement("limit");
      if (limit == nullptr || (type != nullptr && std::string(type) == "continuous")) return false;
      const auto lower = parse_number(limit->Attribute("lower") ? limit->Attribute("lower") : "0",
                                      kUrdfNumber);
      const auto upper = parse_number(limit->Attribute("upper") ? limit->Attribute("upper") : "0",
                                      kUrdfNumber);
      return lower && upper && !(value >= *lower && value <= *upper);
    }
    return false;
  }

  double number(const XMLElement* e, const char* attr, const std::string& owner,
                std::optional<double> fallback) const {
    if (fallback && e->Attribute(attr) == nullptr) return *fallback;
    const char* v = required(e, attr, owner);
    const auto d = parse_number(v, kUrdfNumber);
    if (!d)
      fail(e, owner, std::string("attribute '") + attr + "': expected a number, got '" + v + "'");
    return *d;
  }

  Vector3 vector3(const XMLElement* e, const char* attr, const std::string& owner,
                  std::optional<Vector3> fallback) const {
    if (fallback && e->Attribute(attr) == nullptr) return *fallback;
    const char* v = required(e, attr, owner);
    const auto tokens = io_detail::split_ws(v);
    Vector3 out;
    bool ok = tokens.size() == 3;
    for (std::size_t i = 0; ok && i < 3; ++i) {
      const auto d = parse_number(tokens[i], kUrdfNumber);
      ok = d.has_value();
      if (ok) out[static_cast<Eigen::Index>(i)] = *d;
    }
    if (!ok)
      fail(e, owner, std::string("attribute '") + attr + "': expected 3 numbers, got '" + v + "'");
    return out;
  }

  // Optional <origin xyz rpy> child; identity when absent. The first one counts (as urdfdom).
  Pose origin(const XMLElement* parent, const std::string& owner) const {
    const XMLElement* o = parent->FirstChildElement("origin");
    if (o == nullptr) return Pose::identity();
    return Pose::from_xyz_rpy(vector3(o, "xyz", owner, Vector3::Zero()),
                              vector3(o, "rpy", owner, Vector3::Zero()));
  }

  // A misspelt element (<orgin>, <inertal>) would be skipped and the robot built without it: a
  // joint at the parent's origin, a massless link. URDF's own elements are few and fixed; a
  // namespaced one (gazebo:..., a tool's) is an extension and passes.
  void only_elements(const XMLElement* e, const std::string& owner,
                     const std::vector<std::string>& known) const {
    for (const XMLElement* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
      const std::string name = c->Name();
      if (name.find(':') != std::string::npos ||
          std::find(known.begin(), known.end(), name) != known.end())
        continue;
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      const std::string nearest = nearest_name(name, known);
      fail(c, owner,
           "unknown element <" + shown(name) + "> in <" + e->Name() + "> (a URDF <" + e->Name() +
               "> holds " + list + ")" +
               (nearest.empty() ? std::string() : ": did you mean <" + nearest + ">?"));
    }
  }

  LinkSpec parse_link(const XMLElement* e) {
    LinkSpec link;
    link.source = where(e);
    link.name = required(e, "name", "");
    const std::string owner = "link '" + link.name + "'";
    only_elements(e, owner, {"inertial", "visual", "collision", "self_collision_checking"});
    if (const XMLElement* inertial = e->FirstChildElement("inertial")) {
      only_elements(inertial, owner, {"origin", "mass", "inertia"});
      // URDF gives the inertia about the CoM in the <inertial><origin> frame: move it to the link
      // frame.
      const Pose X_link_inertial = origin(inertial, owner);
      const XMLElement* mass = required_child(inertial, "mass", owner);
      const XMLElement* inertia = required_child(inertial, "inertia", owner);
      Inertia in;
      in.mass = number(mass, "value", owner, std::nullopt);
      if (in.mass < 0.0)
        fail(mass, owner,
             std::string("attribute 'value': must not be negative, got '") +
                 mass->Attribute("value") + "'");
      const double ixx = number(inertia, "ixx", owner, std::nullopt);
      const double ixy = number(inertia, "ixy", owner, std::nullopt);
      const double ixz = number(inertia, "ixz", owner, std::nullopt);
      const double iyy = number(inertia, "iyy", owner, std::nullopt);
      const double iyz = number(inertia, "iyz", owner, std::nullopt);
      const double izz = number(inertia, "izz", owner, std::nullopt);
      in.inertia_com << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
      check_inertia_as_written(in, inertia, owner);
      link.inertia = in.transformed(X_link_inertial);
      link.inertia_source = where(inertia) + ": <inertial>";
    }
    for (const XMLElement* c = e->FirstChildElement("collision"); c != nullptr;
         c = c->NextSiblingElement("collision")) {
      parse_collision(c, link.name, owner);
    }
    return link;
  }

  void parse_collision(const XMLElement* c, const std::string& link, const std::string& owner) {
    const XMLElement* geometry = required_child(c, "geometry", owner);
    const XMLElement* g = geometry->FirstChildElement();
    if (g == nullptr)
      fail(geometry, owner, "missing shape (sphere, box, cylinder, capsule or mesh)");
    io_detail::ShapeSpec spec;
    spec.frame = link;
    spec.source = context(g, owner);
    CollisionShape& s = spec.shape;
    s.placement = origin(c, owner);
    const std::string type = g->Name();
    auto positive = [&](const char* attr) {
      const double v = number(g, attr, owner, std::nullopt);
      if (!(v > 0.0))
        fail(g, owner,
             std::string("attribute '") + attr + "': must be positive, got '" + g->Attribute(attr) +
                 "'");
      return v;
    };
    if (type == "sphere") {
      s.type = ShapeType::kSphere;
      s.radius = positive("radius");
    } else if (type == "box") {
      s.type = ShapeType::kBox;
      s.size = vector3(g, "size", owner, std::nullopt);
      if (!(s.size.minCoeff() > 0.0))
        fail(g, owner,
             std::string("attribute 'size': must be positive, got '") + g->Attribute("size") + "'");
    } else if (type == "cylinder" || type == "capsule") {
      // <capsule radius length/> is our extension (URDF has none): length excludes the caps.
      s.type = type == "cylinder" ? ShapeType::kCylinder : ShapeType::kCapsule;
      s.radius = positive("radius");
      s.length = number(g, "length", owner, std::nullopt);
      if (s.length < 0.0 || (s.type == ShapeType::kCylinder && s.length == 0.0)) {
        fail(g, owner,
             std::string("attribute 'length': must be positive, got '") + g->Attribute("length") +
                 "'");
      }
    } else if (type == "mesh") {
      s.type = ShapeType::kMesh;
      spec.mesh_uri = required(g, "filename", owner);
      if (spec.mesh_uri.empty()) fail(g, owner, "attribute 'filename': must not be empty");
      s.scale = vector3(g, "scale", owner, Vector3::Ones());
      if (s.scale.cwiseAbs().minCoeff() == 0.0)
        fail(g, owner,
             std::string("attribute 'scale': must not be zero, got '") + g->Attribute("scale") +
                 "'");
    } else {
      fail(g, owner,
           "unknown geometry <" + type + "> (expected sphere, box, cylinder, capsule or mesh)");
    }
    shapes_.push_back(std::move(spec));
  }

  JointSpec parse_joint(const XMLElement* e) {
    JointSpec j;
    j.source = where(e);
    j.name = required(e, "name", "");
    const std::string owner = "joint '" + j.name + "'";
    only_elements(e, owner,
                  {"origin", "parent", "child", "axis", "calibration", "dynamics", "limit", "mimic",
                   "safety_controller"});
    const std::string type = required(e, "type", owner);
    if (type == "revolute") {
      j.type = JointSpecType::kRevolute;
    } else if (type == "continuous") {
      j.type = JointSpecType::kContinuous;
    } else if (type == "prismatic") {
      j.type = JointSpecType::kPrismatic;
    } else if (type == "fixed") {
      j.type = JointSpecType::kFixed;
    } else if (type == "floating" || type == "planar") {
      fail(e, owner,
           "attribute 'type': unsupported joint type '" + type + "' (only 1-DoF and fixed joints)");
    } else {
      fail(e, owner,
           "attribute 'type': unknown joint type '" + type +
               "' (expected revolute, continuous, prismatic or fixed)");
    }
    j.parent = required(required_child(e, "parent", owner), "link", owner);
    j.child = required(required_child(e, "child", owner), "link", owner);
    j.origin = origin(e, owner);
    if (const XMLElement* axis = e->FirstChildElement("axis")) {
      j.axis = vector3(axis, "xyz", owner, Vector3::UnitX());
      if (j.type != JointSpecType::kFixed && j.axis.norm() < 1e-12) {
        fail(axis, owner,
             std::string("attribute 'xyz': the axis must not be zero, got '") +
                 axis->Attribute("xyz") + "'");
      }
    }
    const XMLElement* limit = e->FirstChildElement("limit");
    if (limit == nullptr &&
        (j.type == JointSpecType::kRevolute || j.type == JointSpecType::kPrismatic)) {
      fail(e, owner, "missing element <limit> (required for " + type + " joints)");
    }
    if (limit != nullptr && j.type != JointSpecType::kFixed) {
      j.effort_limit = number(limit, "effort", owner, std::nullopt);
      j.velocity_limit = number(limit, "velocity", owner, std::nullopt);
      if (j.type != JointSpecType::kContinuous) {
        j.lower = number(limit, "lower", owner, 0.0);
        j.upper = number(limit, "upper", owner, 0.0);
        if (j.lower > j.upper) {
          // Either may be missing (it then defaults to 0): never append a null attribute.
          const auto text = [&](const char* attr) {
            const char* v = limit->Attribute(attr);
            return v ? "'" + std::string(v) + "'" : std::string("0 (missing, default)");
          };
          fail(limit, owner,
               "attributes 'lower' > 'upper' (" + text("lower") + " > " + text("upper") + ")");
        }
      }
      if (j.effort_limit < 0.0)
        fail(limit, owner,
             std::string("attribute 'effort': must not be negative, got '") +
                 limit->Attribute("effort") + "'");
      if (j.velocity_limit < 0.0)
        fail(limit, owner,
             std::string("attribute 'velocity': must not be negative, got '") +
                 limit->Attribute("velocity") + "'");
    }
    if (const XMLElement* dyn = e->FirstChildElement("dynamics")) {
      j.damping = number(dyn, "damping", owner, 0.0);
      j.friction = number(dyn, "friction", owner, 0.0);
      // Our extension (docs/model.md "Armature"): the reflected rotor inertia, ignored by
      // urdfdom; an attribute of <dynamics>, where the joint's other dynamic parameters are.
      j.armature = number(dyn, "armature", owner, 0.0);
      if (j.armature < 0.0)
        fail(dyn, owner,
             std::string("attribute 'armature': must not be negative, got '") +
                 dyn->Attribute("armature") + "'");
    }
    return j;
  }

  std::string file_;
  std::vector<io_detail::ShapeSpec> shapes_;
};

}  // namespace

RobotDescription load_urdf_string(const std::string& xml, const std::string& name,
                                  const LoadOptions& options) {
  UrdfParser parser(name);
  RobotDescription r = parser.parse(xml, fs::current_path(), options);
  r.source = name;
  return r;
}

RobotDescription load_urdf(const fs::path& path, const LoadOptions& options) {
  const std::string text = read_input_file(path, "robot");
  UrdfParser parser(path.string());
  RobotDescription r =
      parser.parse(text, path.parent_path().empty() ? fs::path(".") : path.parent_path(), options);
  r.source = path;
  return r;
}

}  // namespace extwrench
