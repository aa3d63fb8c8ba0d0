// load_robot and the read-only views of the Model and the collision geometry.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <map>
#include <string>

#include "arrays.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "robot.hpp"

namespace extwrench::python {

Robot::Robot(RobotDescription d, LoadOptions o)
    : description(std::move(d)),
      options(std::move(o)),
      absolute_source(
          description.source.empty()
              ? std::filesystem::path()
              : std::filesystem::weakly_canonical(std::filesystem::absolute(description.source))),
      data(std::make_unique<Data>(description.model)),
      q(VectorX::Zero(description.model.nq())),
      dq(q),
      ddq(q),
      tau(q) {}

int Robot::body(const py::handle& body_or_name, const char* argument) const {
  const Model& m = model();
  if (py::isinstance<py::str>(body_or_name)) {
    const auto name = body_or_name.cast<std::string>();
    if (const auto b = m.find_body(name)) return *b;
    throw py::value_error(std::string(argument) + ": no body or frame named '" + name + "'");
  }
  // Any integer (numpy's too: a value of an estimate's `link` column), not a bool.
  if (!PyIndex_Check(body_or_name.ptr()) || py::isinstance<py::bool_>(body_or_name) ||
      (py::hasattr(body_or_name, "dtype") &&
       body_or_name.attr("dtype").attr("kind").cast<std::string>() == "b")) {
    throw py::type_error(std::string(argument) +
                         ": expected a body index (an integer) or name, got " +
                         std::string(py::str(py::type::handle_of(body_or_name).attr("__name__"))));
  }
  const auto b = py::int_(py::reinterpret_borrow<py::object>(body_or_name)).cast<long long>();
  if (b < 0 || b >= m.num_bodies()) {
    throw py::value_error(std::string(argument) + ": body index " + std::to_string(b) +
                          " out of range [0, " + std::to_string(m.num_bodies() - 1) + "]");
  }
  return static_cast<int>(b);
}

namespace {

VectorX limits(const Robot& r, double Joint::*field) {
  VectorX v(r.nq());
  for (int i = 0; i < r.nq(); ++i) v[i] = r.model().joints[static_cast<std::size_t>(i) + 1].*field;
  return v;
}

py::dict joint_dict(const Joint& j) {
  py::dict d;
  d["name"] = j.name;
  d["type"] = j.type == JointType::kRevolute ? "revolute" : "prismatic";
  d["placement"] = pose_matrix(j.placement);
  d["axis"] = Vector3(j.axis);
  d["lower"] = j.lower;
  d["upper"] = j.upper;
  d["velocity_limit"] = j.velocity_limit;
  d["effort_limit"] = j.effort_limit;
  d["damping"] = j.damping;
  d["friction"] = j.friction;
  return d;
}

py::dict shape_dict(const CollisionShape& s) {
  static const char* const kTypes[] = {"sphere", "box", "cylinder", "capsule", "mesh"};
  py::dict d;
  d["type"] = kTypes[static_cast<int>(s.type)];
  d["link"] = s.link;
  d["body"] = s.body;
  d["placement"] = pose_matrix(s.placement);
  d["radius"] = s.radius;
  d["length"] = s.length;
  d["size"] = Vector3(s.size);
  d["scale"] = Vector3(s.scale);
  if (s.mesh) {
    d["mesh_path"] = s.mesh->path;
    d["vertices"] = to_numpy(s.mesh->vertices.transpose());  // (V, 3), C order as documented
    // (T, 3) vertex indices as numpy's default integer (int64), C order.
    py::array_t<std::int64_t> triangles({s.mesh->triangles.cols(), Eigen::Index{3}});
    auto t = triangles.mutable_unchecked<2>();
    for (Eigen::Index k = 0; k < s.mesh->triangles.cols(); ++k)
      for (Eigen::Index j = 0; j < 3; ++j) t(k, j) = s.mesh->triangles(j, k);
    d["triangles"] = triangles;
  }
  return d;
}

std::shared_ptr<Robot> load(const std::filesystem::path& path,
                            const std::vector<std::filesystem::path>& package_path,
                            bool use_ros_package_path, bool load_meshes, const py::object& gravity,
                            const std::map<std::string, double>& locked_joints,
                            const std::string& root_body, const std::string& tip_body) {
  LoadOptions o;
  o.root_body = root_body;
  o.tip_body = tip_body;
  o.package_path = package_path;
  o.locked_joints = locked_joints;
  o.use_ros_package_path = use_ros_package_path;
  o.load_meshes = load_meshes;
  if (!gravity.is_none()) o.gravity = read_vector3(gravity, "gravity");
  RobotDescription d = load_robot(path, o);
  return std::make_shared<Robot>(std::move(d), std::move(o));
}

/// The second half of Robot's properties: frames, collision geometry, the sensor frame, lookups.
void bind_frames_and_geometry(py::class_<Robot, std::shared_ptr<Robot>>& robot) {
  robot
      .def_property_readonly(
          "frames",
          [](const Robot& r) {
            std::vector<std::string> names;
            for (const Frame& f : r.model().frames) names.push_back(f.name);
            return names;
          },
          "Names of every frame (every URDF link, merged ones included).")
      .def_property_readonly(
          "shapes",
          [](const Robot& r) {
            py::list out;
            for (const auto& s : r.description.geometry.shapes) out.append(shape_dict(s));
            return out;
          },
          "Collision shapes: type, link, body, placement (4 x 4, X_body,shape), radius, length, "
          "size, scale; meshes: mesh_path, vertices (V, 3), triangles (T, 3).")
      .def_property_readonly(
          "default_sensor_pose",
          [](const Robot& r) { return pose_matrix(default_sensor_pose(r.model())); },
          "(4, 4) X_WS: the frame named 'sensor' on link 0, else the identity.")
      .def(
          "body_index", [](const Robot& r, const py::object& b) { return r.body(b, "body"); },
          py::arg("body"), "Index of a body given by name (a body or frame name) or index.")
      .def("__repr__", [](const Robot& r) {
        return "<extwrench.Robot '" + r.model().name + "', " + std::to_string(r.nq()) +
               " joints, from '" + r.description.source.string() + "'>";
      });
}

}  // namespace

void bind_model(py::module_& m) {
  py::class_<Robot, std::shared_ptr<Robot>> robot(m, "Robot", R"(A loaded robot (read-only).

The constant model (bodies, joints, limits, gravity) and its collision geometry, plus the
dynamics workspace that rnea, crba, ... reuse between calls. Body 0 is link 0 (fixed to the base
sensor / ground); body i (1 <= i <= nq) is moved by joint i, whose coordinate is q[i - 1].
World frame W = the robot's root frame.)");
  robot.def_property_readonly("name", [](const Robot& r) { return r.model().name; })
      .def_property_readonly("nq", &Robot::nq, "Number of joint coordinates n.")
      .def_property_readonly(
          "source", [](const Robot& r) { return r.description.source; },
          "The file the robot was loaded from.")
      .def_property_readonly(
          "bodies",
          [](const Robot& r) {
            std::vector<std::string> names;
            for (const Body& b : r.model().bodies) names.push_back(b.name);
            return names;
          },
          "Body names, index 0 = link 0 (n + 1 names).")
      .def_property_readonly(
          "joint_names",
          [](const Robot& r) {
            std::vector<std::string> names;
            for (int i = 1; i <= r.nq(); ++i) names.push_back(r.model().joints[i].name);
            return names;
          },
          "Joint names, joint i moves body i (n names).")
      .def_property_readonly(
          "joints",
          [](const Robot& r) {
            py::list out;
            for (int i = 1; i <= r.nq(); ++i) out.append(joint_dict(r.model().joints[i]));
            return out;
          },
          "Per joint: name, type, placement (4 x 4, X_parent,joint at q = 0), axis (joint "
          "frame), lower/upper [rad | m], velocity_limit, effort_limit, damping, friction.")
      .def_property_readonly(
          "parents", [](const Robot& r) { return r.model().parents; },
          "Parent body of each body (parents[0] = -1).")
      .def_property_readonly(
          "lower", [](const Robot& r) { return limits(r, &Joint::lower); },
          "(n,) lower position limits [rad | m] (-inf when none).")
      .def_property_readonly(
          "upper", [](const Robot& r) { return limits(r, &Joint::upper); },
          "(n,) upper position limits [rad | m] (inf when none).")
      .def_property_readonly("velocity_limit",
                             [](const Robot& r) { return limits(r, &Joint::velocity_limit); })
      .def_property_readonly("effort_limit",
                             [](const Robot& r) { return limits(r, &Joint::effort_limit); })
      .def_property_readonly(
          "masses",
          [](const Robot& r) {
            VectorX m(r.model().num_bodies());
            for (int i = 0; i < m.size(); ++i) m[i] = r.model().bodies[i].inertia.mass;
            return m;
          },
          "(n + 1,) body masses [kg].")
      .def_property_readonly(
          "gravity", [](const Robot& r) { return Vector3(r.model().gravity); },
          "(3,) gravity acceleration in W [m/s^2].");
  bind_frames_and_geometry(robot);

  m.def("load_robot", &load, py::arg("path"), py::kw_only(),
        py::arg("package_path") = std::vector<std::filesystem::path>{},
        py::arg("use_ros_package_path") = true, py::arg("load_meshes") = true,
        py::arg("gravity") = py::none(), py::arg("locked_joints") = std::map<std::string, double>{},
        py::arg("root_body") = std::string(), py::arg("tip_body") = std::string(),
        R"(Loads a URDF (.urdf, .xml), a DH table (.yaml, .yml), or an MJCF (.xml, .mjcf with root
<mujoco>) when the module was built with MuJoCo, as the CLI is.

package_path: directories searched for package://NAME/... (NAME is a subdirectory of each);
ROS_PACKAGE_PATH is appended when use_ros_package_path. gravity: (3,) in W, overrides the file's.
locked_joints: {joint name: value [rad | m]}: those joints become fixed at those values and their
bodies are merged (the reduced serial model of a tree, e.g. a gripper's fingers; docs/model.md).
root_body, tip_body: MJCF only, the chain of a scene (docs/mujoco.md), as --root-body, --tip-body.
Raises extwrench.Error with the loader's message (file:line: field: what).)");
}

}  // namespace extwrench::python
