#include "extwrench/io/urdf_writer.hpp"

#include <tinyxml2.h>

#include <cmath>
#include <fstream>
#include <set>

#include "extwrench/core/error.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench {
namespace {

std::string num(double x) { return format_number(x); }

std::string vec(const Vector3& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

void add_origin(tinyxml2::XMLElement* parent, const Pose& pose) {
  tinyxml2::XMLElement* origin = parent->InsertNewChildElement("origin");
  origin->SetAttribute("xyz", vec(pose.translation).c_str());
  origin->SetAttribute("rpy", vec(rpy_from_rotation(pose.rotation)).c_str());
}

void add_geometry(tinyxml2::XMLElement* collision, const CollisionShape& shape) {
  tinyxml2::XMLElement* geometry = collision->InsertNewChildElement("geometry");
  switch (shape.type) {
    case ShapeType::kSphere:
      geometry->InsertNewChildElement("sphere")->SetAttribute("radius", num(shape.radius).c_str());
      break;
    case ShapeType::kBox:
      geometry->InsertNewChildElement("box")->SetAttribute("size", vec(shape.size).c_str());
      break;
    case ShapeType::kCylinder:
    case ShapeType::kCapsule: {
      tinyxml2::XMLElement* e = geometry->InsertNewChildElement(
          shape.type == ShapeType::kCylinder ? "cylinder" : "capsule");
      e->SetAttribute("radius", num(shape.radius).c_str());
      e->SetAttribute("length", num(shape.length).c_str());
      break;
    }
    case ShapeType::kMesh: {
      if (!shape.mesh || shape.mesh->path.empty()) {
        throw Error("write_urdf: a mesh shape of link '" + shape.link +
                    "' has no file to refer to");
      }
      const std::filesystem::path p = std::filesystem::absolute(shape.mesh->path);
      tinyxml2::XMLElement* e = geometry->InsertNewChildElement("mesh");
      e->SetAttribute("filename", ("file://" + p.string()).c_str());
      e->SetAttribute("scale", vec(shape.scale).c_str());
      break;
    }
  }
}

// <link> of body b: its merged mass properties and its collision shapes.
void add_link(tinyxml2::XMLElement* robot, const Model& model, const GeometryModel& geometry,
              int b) {
  const Body& body = model.bodies[static_cast<std::size_t>(b)];
  tinyxml2::XMLElement* link = robot->InsertNewChildElement("link");
  link->SetAttribute("name", body.name.c_str());
  const Inertia& in = body.inertia;
  if (in.mass > 0.0) {
    tinyxml2::XMLElement* inertial = link->InsertNewChildElement("inertial");
    tinyxml2::XMLElement* origin = inertial->InsertNewChildElement("origin");
    origin->SetAttribute("xyz", vec(in.com).c_str());
    origin->SetAttribute("rpy", "0 0 0");
    inertial->InsertNewChildElement("mass")->SetAttribute("value", num(in.mass).c_str());
    tinyxml2::XMLElement* inertia = inertial->InsertNewChildElement("inertia");
    const Matrix3& I = in.inertia_com;
    inertia->SetAttribute("ixx", num(I(0, 0)).c_str());
    inertia->SetAttribute("ixy", num(I(0, 1)).c_str());
    inertia->SetAttribute("ixz", num(I(0, 2)).c_str());
    inertia->SetAttribute("iyy", num(I(1, 1)).c_str());
    inertia->SetAttribute("iyz", num(I(1, 2)).c_str());
    inertia->SetAttribute("izz", num(I(2, 2)).c_str());
  }
  if (b < static_cast<int>(geometry.body_shapes.size())) {
    for (const int s : geometry.body_shapes[static_cast<std::size_t>(b)]) {
      const CollisionShape& shape = geometry.shapes[static_cast<std::size_t>(s)];
      tinyxml2::XMLElement* collision = link->InsertNewChildElement("collision");
      add_origin(collision, shape.placement);
      add_geometry(collision, shape);
    }
  }
}

// <limit> of a joint, when URDF wants one.
void add_limit(tinyxml2::XMLElement* joint, const Joint& j) {
  const bool unlimited = !std::isfinite(j.lower) || !std::isfinite(j.upper);
  const bool revolute = j.type == JointType::kRevolute;
  const bool finite_rates = std::isfinite(j.velocity_limit) && std::isfinite(j.effort_limit);
  if (!(revolute && unlimited) || finite_rates) {
    // URDF wants velocity and effort on a limited joint: an unbounded one is written as a
    // huge bound, read back as a number.
    constexpr double kUnbounded = 1e300;
    tinyxml2::XMLElement* limit = joint->InsertNewChildElement("limit");
    if (!(revolute && unlimited)) {
      limit->SetAttribute("lower", num(std::isfinite(j.lower) ? j.lower : -kUnbounded).c_str());
      limit->SetAttribute("upper", num(std::isfinite(j.upper) ? j.upper : kUnbounded).c_str());
    }
    limit->SetAttribute(
        "velocity", num(std::isfinite(j.velocity_limit) ? j.velocity_limit : kUnbounded).c_str());
    limit->SetAttribute("effort",
                        num(std::isfinite(j.effort_limit) ? j.effort_limit : kUnbounded).c_str());
  }
}

// <joint> moving body b (b > 0) from its parent body.
void add_joint(tinyxml2::XMLElement* robot, const Model& model, int b) {
  const Joint& j = model.joints[static_cast<std::size_t>(b)];
  tinyxml2::XMLElement* joint = robot->InsertNewChildElement("joint");
  joint->SetAttribute("name", j.name.c_str());
  const bool unlimited = !std::isfinite(j.lower) || !std::isfinite(j.upper);
  const bool revolute = j.type == JointType::kRevolute;
  joint->SetAttribute("type", revolute ? (unlimited ? "continuous" : "revolute") : "prismatic");
  joint->InsertNewChildElement("parent")->SetAttribute(
      "link", model.bodies[static_cast<std::size_t>(model.parents[static_cast<std::size_t>(b)])]
                  .name.c_str());
  joint->InsertNewChildElement("child")->SetAttribute(
      "link", model.bodies[static_cast<std::size_t>(b)].name.c_str());
  add_origin(joint, j.placement);
  joint->InsertNewChildElement("axis")->SetAttribute("xyz", vec(j.axis).c_str());
  add_limit(joint, j);
  if (j.damping != 0.0 || j.friction != 0.0 || j.armature != 0.0) {
    tinyxml2::XMLElement* dyn = joint->InsertNewChildElement("dynamics");
    dyn->SetAttribute("damping", num(j.damping).c_str());
    dyn->SetAttribute("friction", num(j.friction).c_str());
    // Our extension (docs/model.md "Armature"); urdfdom and KDL read only the two above.
    if (j.armature != 0.0) dyn->SetAttribute("armature", num(j.armature).c_str());
  }
}

// Extra frames (merged URDF links, sensor and tool frames): massless links on fixed joints.
// `names` holds the link names written so far.
void add_frame_links(tinyxml2::XMLElement* robot, const Model& model,
                     std::set<std::string>& names) {
  for (const Frame& f : model.frames) {
    if (names.count(f.name) != 0) continue;
    names.insert(f.name);
    robot->InsertNewChildElement("link")->SetAttribute("name", f.name.c_str());
    tinyxml2::XMLElement* joint = robot->InsertNewChildElement("joint");
    joint->SetAttribute("name", (f.name + "_fixed_joint").c_str());
    joint->SetAttribute("type", "fixed");
    joint->InsertNewChildElement("parent")->SetAttribute(
        "link", model.bodies[static_cast<std::size_t>(f.body)].name.c_str());
    joint->InsertNewChildElement("child")->SetAttribute("link", f.name.c_str());
    add_origin(joint, f.placement);
  }
}

}  // namespace

std::string write_urdf_string(const Model& model, const GeometryModel& geometry) {
  tinyxml2::XMLDocument doc;
  doc.InsertEndChild(doc.NewDeclaration());
  doc.InsertEndChild(doc.NewComment(
      " Written by extwrench (io/urdf_writer): bodies with merged mass properties, link frames "
      "as massless links on fixed joints. <capsule> is an extwrench extension. "));
  tinyxml2::XMLElement* robot = doc.NewElement("robot");
  doc.InsertEndChild(robot);
  robot->SetAttribute("name", model.name.empty() ? "robot" : model.name.c_str());
  std::set<std::string> names;
  for (int b = 0; b < model.num_bodies(); ++b) {
    names.insert(model.bodies[static_cast<std::size_t>(b)].name);
    add_link(robot, model, geometry, b);
    if (b > 0) add_joint(robot, model, b);
  }
  add_frame_links(robot, model, names);
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

void write_urdf(const std::filesystem::path& path, const Model& model,
                const GeometryModel& geometry) {
  const std::string text = write_urdf_string(model, geometry);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error(path.string() + ": cannot create the file");
  out << text;
  out.flush();
  if (!out) throw Error(path.string() + ": write failed");
}

}  // namespace extwrench
