// extwrench info ROBOT: what a robot file contains, as the library understood it.
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"

namespace extwrench::cli {
namespace {

struct InfoOptions {
  std::filesystem::path robot;
  std::vector<std::filesystem::path> package_path;
  std::vector<std::string> lock;
  std::string root_body;  ///< MJCF only
  std::string tip_body;   ///< MJCF only
};

std::string joint_type_name(JointType type) {
  switch (type) {
    case JointType::kRevolute:
      return "revolute";
    case JointType::kPrismatic:
      return "prismatic";
  }
  return "unknown";
}

std::string shape_text(const CollisionShape& s) {
  switch (s.type) {
    case ShapeType::kSphere:
      return "sphere radius " + fmt(s.radius);
    case ShapeType::kBox:
      return "box size " + fmt(s.size);
    case ShapeType::kCylinder:
      return "cylinder radius " + fmt(s.radius) + " length " + fmt(s.length);
    case ShapeType::kCapsule:
      return "capsule radius " + fmt(s.radius) + " length " + fmt(s.length);
    case ShapeType::kMesh: {
      std::string text = "mesh";
      if (s.mesh) {
        text +=
            " '" + s.mesh->path + "', " + std::to_string(s.mesh->triangles.cols()) + " triangles";
      }
      if (!s.scale.isOnes()) text += ", scale " + fmt(s.scale);
      return text;
    }
  }
  return "unknown shape";
}

std::string pose_text(const Pose& x) {
  return "xyz " + fmt(x.translation) + " rpy " + fmt(rpy_from_rotation(x.rotation));
}

std::string limits_text(const Joint& j) {
  const bool revolute = j.type == JointType::kRevolute;
  const std::string pos = revolute ? " rad" : " m";
  const std::string vel = revolute ? " rad/s" : " m/s";
  const std::string eff = revolute ? " N m" : " N";
  std::string t;
  if (std::isinf(j.lower) && std::isinf(j.upper)) {
    t = "no position limits";
  } else {
    t = "limits [" + fmt(j.lower) + ", " + fmt(j.upper) + "]" + pos;
  }
  if (!std::isinf(j.velocity_limit)) t += ", velocity " + fmt(j.velocity_limit) + vel;
  if (!std::isinf(j.effort_limit)) t += ", effort " + fmt(j.effort_limit) + eff;
  t += ", damping " + fmt(j.damping) + (revolute ? " N m s/rad" : " N s/m");
  t += ", friction " + fmt(j.friction) + eff;
  if (j.armature != 0.0) t += ", armature " + fmt(j.armature) + (revolute ? " kg m^2" : " kg");
  return t;
}

void run_info(const InfoOptions& opt) {
  const LoadOptions load =
      robot_load_options(opt.package_path, opt.lock, opt.root_body, opt.tip_body);
  const RobotDescription robot = load_robot_file(opt.robot, load);
  const Model& model = robot.model;
  std::ostringstream out;

  out << "robot: " << (model.name.empty() ? "(unnamed)" : model.name) << "  (" << opt.robot.string()
      << ")\n";
  out << "joints: " << model.nq() << (model.is_serial_chain() ? ", serial chain" : ", tree")
      << "\n";
  out << "gravity: " << fmt(model.gravity) << " m/s^2 in the root frame\n";

  out << "\nBodies (links welded by fixed joints are merged into one body; mass [kg], centre of\n"
         "mass [m] in the body frame, inertia about the centre of mass [kg m^2]):\n";
  for (int i = 0; i < model.num_bodies(); ++i) {
    const Body& b = model.bodies[static_cast<std::size_t>(i)];
    const Matrix3& I = b.inertia.inertia_com;
    out << "  " << i << "  " << b.name << "  mass " << fmt(b.inertia.mass) << "  com "
        << fmt(b.inertia.com) << "\n     ixx " << fmt(I(0, 0)) << " iyy " << fmt(I(1, 1)) << " izz "
        << fmt(I(2, 2)) << " ixy " << fmt(I(0, 1)) << " ixz " << fmt(I(0, 2)) << " iyz "
        << fmt(I(1, 2)) << "\n";
  }
  out << "total mass: " << fmt(model.total_mass()) << " kg\n";

  out << "\nJoints (qi is column i of the CSV formats; axis in the child body frame):\n";
  for (int i = 1; i < model.num_bodies(); ++i) {
    const Joint& j = model.joints[static_cast<std::size_t>(i)];
    const int parent = model.parents[static_cast<std::size_t>(i)];
    out << "  q" << i << "  " << j.name << "  " << joint_type_name(j.type) << "  "
        << model.bodies[static_cast<std::size_t>(parent)].name << " -> "
        << model.bodies[static_cast<std::size_t>(i)].name << "  axis " << fmt(j.axis) << "\n     "
        << limits_text(j) << "\n";
  }

  out << "\nFrames (every link and named frame; pose in its body's frame, xyz [m], rpy [rad]):\n";
  for (const Frame& f : model.frames) {
    out << "  " << f.name << "  on " << model.bodies[static_cast<std::size_t>(f.body)].name << "  "
        << pose_text(f.placement) << "\n";
  }

  out << "\nBase sensor pose (default of `extwrench dynamics`, in the root frame):\n";
  try {
    std::string which;
    const Pose X_WS = default_sensor_pose(model, &which);
    out << "  " << which << ": " << pose_text(X_WS) << "\n";
  } catch (const std::exception& e) {
    out << "  none: " << e.what() << "\n";
  }

  out << "\nCollision shapes (pose in the body frame):\n";
  if (robot.geometry.shapes.empty()) out << "  none\n";
  for (const CollisionShape& s : robot.geometry.shapes) {
    out << "  " << model.bodies[static_cast<std::size_t>(s.body)].name;
    if (!s.link.empty() && s.link != model.bodies[static_cast<std::size_t>(s.body)].name)
      out << " (link " << s.link << ")";
    out << ": " << shape_text(s) << "  " << pose_text(s.placement) << "\n";
  }
  std::cout << out.str();
}

}  // namespace

void register_info(CLI::App& app) {
  auto opt = std::make_shared<InfoOptions>();
  CLI::App* sub = app.add_subcommand("info",
                                     "Print what a robot file contains: links, joints, masses, "
                                     "frames, sensor pose, collision shapes");
  sub->add_option("ROBOT", opt->robot, kRobotFileHelp)->required()->type_name("FILE");
  add_package_path_option(*sub, opt->package_path);
  add_lock_option(*sub, opt->lock);
  add_chain_options(*sub, opt->root_body, opt->tip_body);
  sub->footer(help_footer(
      {{"extwrench info models/paper_arm.urdf",
        "the paper's arm: bodies, joints q1..q7 (the CSV columns' order), frames, sensor pose, "
        "shapes"},
       {"extwrench info panda.urdf --package-path ~/ws/src --lock panda_finger_joint1=0.02 "
        "--lock panda_finger_joint2=0.02",
        "a robot whose meshes are package:// URIs, its fingers held fixed (a tree made a chain)"},
       {"extwrench info models/paper_arm.xml",
        "the same arm from MJCF (when extwrench is built with MuJoCo; docs/mujoco.md)"}},
      "docs/cli.md (info), docs/model.md (what a robot file may contain)"));
  sub->callback([opt] { run_info(*opt); });
}

}  // namespace extwrench::cli
