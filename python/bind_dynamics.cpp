// The dynamics algorithms on a Robot's reused Data workspace (docs/algorithms.md).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "extwrench/dynamics/crba.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "robot.hpp"

namespace extwrench::python {
namespace {

/// The Python list of ExternalWrench as the C++ span rnea takes (bodies checked).
std::vector<ExternalWrench> wrenches_of(const Robot& r, const py::object& wrenches) {
  std::vector<ExternalWrench> out;
  if (wrenches.is_none()) return out;
  if (py::isinstance<ExternalWrench>(wrenches)) {
    out.push_back(wrenches.cast<ExternalWrench>());
  } else {
    for (const py::handle h : wrenches) {
      if (!py::isinstance<ExternalWrench>(h)) {
        throw py::type_error("wrenches: expected extwrench.ExternalWrench items");
      }
      out.push_back(h.cast<ExternalWrench>());
    }
  }
  for (const auto& w : out) {
    if (w.body < 0 || w.body >= r.model().num_bodies()) {
      throw py::value_error("wrenches: body index " + std::to_string(w.body) + " out of range");
    }
  }
  return out;
}

py::array_t<double> rnea_py(Robot& r, const py::handle& q, const py::handle& dq,
                            const py::handle& ddq, const py::object& wrenches) {
  read_vector(q, "q", r.nq(), r.q);
  read_vector(dq, "dq", r.nq(), r.dq);
  read_vector(ddq, "ddq", r.nq(), r.ddq);
  if (wrenches.is_none()) return to_numpy(rnea(r.model(), *r.data, r.q, r.dq, r.ddq));
  const auto w = wrenches_of(r, wrenches);
  return to_numpy(rnea(r.model(), *r.data, r.q, r.dq, r.ddq, w));
}

py::array_t<double> forward_kinematics_py(Robot& r, const py::handle& q) {
  read_vector(q, "q", r.nq(), r.q);
  forward_kinematics(r.model(), *r.data, r.q);
  const int nb = r.model().num_bodies();
  py::array_t<double> out({nb, 4, 4});
  auto a = out.mutable_unchecked<3>();
  for (int b = 0; b < nb; ++b) {
    const Pose& X = r.data->X_WB[static_cast<std::size_t>(b)];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) a(b, i, j) = X.rotation(i, j);
      a(b, i, 3) = X.translation[i];
      a(b, 3, i) = 0.0;
    }
    a(b, 3, 3) = 1.0;
  }
  return out;
}

// The frame `body` names when it is a name but not a body's.
std::optional<int> frame_not_body(const Model& m, const py::object& body) {
  if (!py::isinstance<py::str>(body)) return std::nullopt;
  const auto name = body.cast<std::string>();
  for (const Body& b : m.bodies)
    if (b.name == name) return std::nullopt;
  return m.find_frame(name);
}

py::array_t<double> jacobian_py(Robot& r, const py::handle& q, const py::object& body,
                                const py::object& point_W) {
  const int b = r.body(body, "body");
  read_vector(q, "q", r.nq(), r.q);
  forward_kinematics(r.model(), *r.data, r.q);
  Vector3 point;
  if (!point_W.is_none()) {
    point = read_vector3(point_W, "point_W");
  } else if (const auto f = frame_not_body(r.model(), body)) {
    // A frame's name (a merged link, a tool frame): the frame's origin, not its body's.
    point = frame_pose(r.model(), *r.data, *f).translation;
  } else {
    return to_numpy(body_jacobian(r.model(), *r.data, b));
  }
  point_jacobian(r.model(), *r.data, b, point, r.data->J);
  return to_numpy(r.data->J);
}

py::array_t<double> frame_pose_py(Robot& r, const py::handle& q, const py::object& frame) {
  read_vector(q, "q", r.nq(), r.q);
  forward_poses(r.model(), *r.data, r.q);
  if (const auto f = frame_not_body(r.model(), frame))
    return pose_matrix(frame_pose(r.model(), *r.data, *f));
  return pose_matrix(r.data->X_WB[static_cast<std::size_t>(r.body(frame, "frame"))]);
}

py::array_t<double> forward_dynamics_py(Robot& r, const py::handle& q, const py::handle& dq,
                                        const py::handle& tau) {
  read_vector(q, "q", r.nq(), r.q);
  read_vector(dq, "dq", r.nq(), r.dq);
  read_vector(tau, "tau", r.nq(), r.tau);
  if (!forward_dynamics(r.model(), *r.data, r.q, r.dq, r.tau)) {
    throw py::value_error("forward_dynamics: the mass matrix B(q) is not positive definite");
  }
  return to_numpy(r.data->ddq);
}

py::array_t<double> sensor_reading_py(Robot& r, const py::handle& q, const py::handle& dq,
                                      const py::handle& ddq, const py::object& wrenches,
                                      const py::object& X_WS) {
  const Pose pose = X_WS.is_none() ? default_sensor_pose(r.model()) : read_pose(X_WS, "X_WS");
  (void)rnea_py(r, q, dq, ddq, wrenches);
  return to_numpy(VectorX(sensor_reading(*r.data, pose)));
}

}  // namespace

void bind_dynamics(py::module_& m) {
  py::class_<ExternalWrench>(m, "ExternalWrench",
                             "An external wrench on a body: force_W applied at point_W plus a "
                             "pure moment moment_W, all in the world frame W.")
      .def(py::init([](int body, const py::object& force_W, const py::object& point_W,
                       const py::object& moment_W) {
             ExternalWrench w;
             w.body = body;
             w.force_W = read_vector3(force_W, "force_W");
             w.point_W = read_vector3(point_W, "point_W");
             w.moment_W = read_vector3(moment_W, "moment_W");
             return w;
           }),
           py::arg("body"), py::arg("force_W"), py::arg("point_W") = Vector3::Zero().eval(),
           py::arg("moment_W") = Vector3::Zero().eval())
      .def_readonly("body", &ExternalWrench::body)
      .def_readonly("force_W", &ExternalWrench::force_W)
      .def_readonly("point_W", &ExternalWrench::point_W)
      .def_readonly("moment_W", &ExternalWrench::moment_W)
      .def("__repr__", [](const ExternalWrench& w) {
        const auto v = [](const Vector3& x) {
          return std::string(py::str(py::make_tuple(x[0], x[1], x[2])));
        };
        return "<extwrench.ExternalWrench body=" + std::to_string(w.body) +
               " force_W=" + v(w.force_W) + " point_W=" + v(w.point_W) +
               " moment_W=" + v(w.moment_W) + ">";
      });

  m.def("rnea", &rnea_py, py::arg("robot"), py::arg("q"), py::arg("dq"), py::arg("ddq"),
        py::arg("wrenches") = py::none(),
        R"(Inverse dynamics tau = B(q) ddq + C(q, dq) dq + g(q) - sum_k J_k^T W_k (eqs. 7-12).

q, dq, ddq: (n,). wrenches: ExternalWrench or a list of them (world frame). Returns tau (n,).)");
  m.def(
      "crba",
      [](Robot& r, const py::handle& q) {
        read_vector(q, "q", r.nq(), r.q);
        return to_numpy(crba(r.model(), *r.data, r.q));
      },
      py::arg("robot"), py::arg("q"), "Mass matrix B(q), (n, n).");
  m.def(
      "bias",
      [](Robot& r, const py::handle& q, const py::handle& dq) {
        read_vector(q, "q", r.nq(), r.q);
        read_vector(dq, "dq", r.nq(), r.dq);
        return to_numpy(bias_torques(r.model(), *r.data, r.q, r.dq));
      },
      py::arg("robot"), py::arg("q"), py::arg("dq"), "Bias torques c = C(q, dq) dq + g(q), (n,).");
  m.def(
      "gravity",
      [](Robot& r, const py::handle& q) {
        read_vector(q, "q", r.nq(), r.q);
        return to_numpy(gravity_torques(r.model(), *r.data, r.q));
      },
      py::arg("robot"), py::arg("q"), "Gravity torques g(q), (n,).");
  m.def(
      "coriolis_matrix",
      [](Robot& r, const py::handle& q, const py::handle& dq) {
        read_vector(q, "q", r.nq(), r.q);
        read_vector(dq, "dq", r.nq(), r.dq);
        return to_numpy(coriolis_matrix(r.model(), *r.data, r.q, r.dq));
      },
      py::arg("robot"), py::arg("q"), py::arg("dq"),
      "Coriolis matrix C(q, dq), (n, n), the factorisation with dB/dt = C + C^T.");
  m.def("jacobian", &jacobian_py, py::arg("robot"), py::arg("q"), py::arg("body"),
        py::arg("point_W") = py::none(),
        R"(Jacobian (6, n) = [J_v; J_w] of a point rigidly attached to `body` (index or name).

point_W: (3,) the point in W (default: the origin of the body, or of the frame named). J_v gives the point's linear
velocity, J_w the body's angular velocity, both in world-aligned axes.)");
  m.def("forward_kinematics", &forward_kinematics_py, py::arg("robot"), py::arg("q"),
        "Poses X_WB of every body, (n + 1, 4, 4) homogeneous transforms (body 0 = link 0).");
  m.def("frame_pose", &frame_pose_py, py::arg("robot"), py::arg("q"), py::arg("frame"),
        R"(Pose X_WF (4, 4) of a frame (a tool frame, a link merged into its parent, an MJCF body's
own frame) or of a body, by name or body index, in the world frame W (Pinocchio's oMf).)");
  m.def("forward_dynamics", &forward_dynamics_py, py::arg("robot"), py::arg("q"), py::arg("dq"),
        py::arg("tau"), "Joint accelerations ddq = B^-1 (tau - c(q, dq)), (n,).");
  m.def("sensor_reading", &sensor_reading_py, py::arg("robot"), py::arg("q"), py::arg("dq"),
        py::arg("ddq"), py::arg("wrenches") = py::none(), py::arg("X_WS") = py::none(),
        R"(What the robot discharges onto a base sensor: [f_m; n_m] (6,) in the sensor frame S,
moment about the sensor origin. X_WS: (4, 4) sensor pose in W (default:
robot.default_sensor_pose). Runs rnea(q, dq, ddq, wrenches) first.)");
}

}  // namespace extwrench::python
