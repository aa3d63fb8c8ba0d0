// ContactEstimator and its estimates; the configuration is a dict of the YAML schema
// (docs/config.md) or a file, read by the project's own loader so that errors are identical.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>

#include "arrays.hpp"
#include "estimator.hpp"
#include "extwrench/io/log.hpp"
#include "robot.hpp"

namespace extwrench::python {

Estimator::Estimator(EstimatorConfig c) : config(std::move(c)), estimator(make_estimator(config)) {
  auto names = std::make_shared<std::vector<std::string>>();
  for (const Body& b : config.robot.model.bodies) names->push_back(b.name);
  body_names = std::move(names);
}

std::string status_text(Status s) {
  if (s.ok()) return "ok";  // the flags are Estimate.flags; the CSV's column shows them instead
  ContactEstimate e;
  e.status = s;
  return EstimatesWriter::status_text(e);
}

Vector6 read_reading(const py::handle& obj, SensorType type) {
  Vector6 reading = Vector6::Zero();
  if (obj.is_none()) {
    if (type == SensorType::kNone) return reading;
    throw py::value_error(std::string("reading: the configured sensor (") +
                          (type == SensorType::kForce ? "force" : "ft") +
                          ") needs a base reading [f; n] in the sensor frame");
  }
  if (py::array_t<double>::check_(obj)) {
    // Fast path of update(): a float64 (6,) or (3,) array, read in place.
    const auto arr = py::reinterpret_borrow<py::array>(obj);
    const py::ssize_t size = arr.ndim() == 1 ? arr.shape(0) : 0;
    if (size == 6 || (size == 3 && type != SensorType::kForceTorque)) {
      const auto* p = static_cast<const char*>(arr.data());
      for (py::ssize_t i = 0; i < size; ++i) {
        std::memcpy(&reading[i], p + i * arr.strides(0), sizeof(double));  // may be unaligned
      }
      if (reading.allFinite()) return reading;
    }
  }
  const RealArray a = real_array(obj, "reading", 1);
  if (!(a.rows == 6 || (a.rows == 3 && type != SensorType::kForceTorque))) {
    throw py::value_error("reading: expected shape (6,)" +
                          std::string(type == SensorType::kForceTorque ? "" : " or (3,)") +
                          ", got " + shape_text(a.rows));
  }
  check_finite(a, "reading");
  for (py::ssize_t i = 0; i < a.rows; ++i) reading[i] = a.at(i);
  return reading;
}

namespace {

/// Input errors become Python exceptions naming the channel; the estimator's state is unchanged
/// by them (ContactEstimator validates every input before touching its state).
void raise_if_input_error(Status s, const char* call) {
  switch (s.code) {
    case StatusCode::kWrongSize:
    case StatusCode::kNonFinite:
    case StatusCode::kNonIncreasingTime:
      throw py::value_error(std::string(call) + ": " + status_text(s) +
                            " (the estimator's state is unchanged)");
    case StatusCode::kNotInitialized:
      throw py::value_error(std::string(call) + ": not_initialized: call reset() first");
    default:
      return;
  }
}

std::string json_text(const py::handle& config) {
  const py::module_ json = py::module_::import("json");
  // numpy scalars and arrays in the dict are written as plain numbers and lists.
  const py::cpp_function to_plain([](const py::handle& o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error("config: a value of type " +
                         std::string(py::str(py::type::handle_of(o).attr("__name__"))) +
                         " is not a number, string, list or dict");
  });
  // JSON is YAML's flow style: the project's YAML loader reads it, one key per line.
  return json.attr("dumps")(config, py::arg("indent") = 1, py::arg("default") = to_plain)
      .cast<std::string>();
}

std::unique_ptr<Estimator> make(const py::object& robot, const py::object& config) {
  LoadOptions load;
  const Robot* r = robot.is_none() ? nullptr : robot.cast<const Robot*>();
  if (r != nullptr) load = r->options;
  if (py::isinstance<py::dict>(config)) {
    // A copy: the caller's dict is left as it was.
    auto d = py::reinterpret_steal<py::dict>(PyDict_Copy(config.ptr()));
    if (!d) throw py::error_already_set();
    if (r != nullptr && d.contains("robot")) {
      throw py::value_error(
          "config: robot: give the robot either as the argument or as the "
          "config's 'robot' key, not both");
    }
    if (r != nullptr) d["robot"] = r->absolute_source.string();
    return std::make_unique<Estimator>(load_estimator_config_string(json_text(d), "config", load));
  }
  if (!py::isinstance<py::str>(config) && !py::hasattr(config, "__fspath__")) {
    throw py::type_error("config: expected a dict of the configuration schema or a path");
  }
  auto e = std::make_unique<Estimator>(
      load_estimator_config(config.cast<std::filesystem::path>(), load));
  // The Robot's load options (gravity, locks) were applied to the configuration's robot file:
  // that must be the Robot's own file, not merely one with as many joints.
  std::error_code ec;
  if (r != nullptr && !std::filesystem::equivalent(e->config.robot_path, r->absolute_source, ec)) {
    throw py::value_error("config: its robot is " + e->config.robot_path.string() +
                          ", the robot given was loaded from " + r->absolute_source.string() +
                          " (give the configuration alone, or the robot with a config dict)");
  }
  return e;
}

Estimate update(Estimator& e, double t, const py::handle& q, const py::handle& dq,
                const py::handle& tau, const py::handle& reading) {
  read_vector(q, "q", e.nq(), e.q);
  read_vector(dq, "dq", e.nq(), e.dq);
  read_vector(tau, "tau", e.nq(), e.tau);
  const Vector6 reading_S = read_reading(reading, e.config.options.sensor.type);
  const Status s = e.estimator.update(t, e.q, e.dq, e.tau, reading_S);
  raise_if_input_error(s, "update");
  return {e.estimator.result(), e.body_names};
}

void reset(Estimator& e, double t, const py::handle& q, const py::handle& dq,
           const py::handle& tau) {
  read_vector(q, "q", e.nq(), e.q);
  read_vector(dq, "dq", e.nq(), e.dq);
  read_vector(tau, "tau", e.nq(), e.tau);
  raise_if_input_error(e.estimator.reset(t, e.q, e.dq, e.tau), "reset");
}

py::frozenset flag_names(std::uint32_t flags) {
  py::set out;
  if (flags == 0) return py::frozenset(out);
  const std::string text = describe_flags(flags);
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find('|', begin), text.size());
    out.add(py::str(text.substr(begin, end - begin)));
    begin = end + 1;
  }
  return py::frozenset(out);
}

void bind_estimate(py::module_& m) {
  py::class_<Estimate>(m, "Estimate",
                       "One sample of the estimator, world frame W. Quantities not estimated are "
                       "NaN and their flag is absent.")
      .def_property_readonly(
          "t", [](const Estimate& e) { return e.value.t; }, "[s]")
      .def_property_readonly("contact", [](const Estimate& e) { return e.value.contact; })
      .def_property_readonly(
          "link", [](const Estimate& e) { return e.value.link; },
          "Contact link (body index), -1 if none.")
      .def_property_readonly(
          "link_name",
          [](const Estimate& e) -> py::object {
            const int l = e.value.link;
            if (l < 0 || l >= static_cast<int>(e.body_names->size())) return py::none();
            return py::str((*e.body_names)[static_cast<std::size_t>(l)]);
          },
          "Name of the contact link, None if none.")
      .def_property_readonly(
          "link_candidates",
          [](const Estimate& e) {
            std::vector<int> out;
            for (int l = 0; l < 64; ++l) {
              if ((e.value.link_candidates >> l & 1u) != 0) out.push_back(l);
            }
            return out;
          },
          "Geometry isolation: the other links (body indices) consistent with the residual and "
          "the line of action; empty when none.")
      .def_property_readonly(
          "force_W", [](const Estimate& e) { return e.value.force_W; }, "(3,) F_ext [N].")
      .def_property_readonly(
          "sigma_force", [](const Estimate& e) { return e.value.sigma_force; },
          "1-sigma of force_W, sqrt(trace) of its covariance [N] (docs/estimator.md#uncertainty).")
      .def_property_readonly(
          "sigma_moment", [](const Estimate& e) { return e.value.sigma_moment; },
          "1-sigma of moment_W [N m].")
      .def_property_readonly(
          "sigma_line", [](const Estimate& e) { return e.value.sigma_line; },
          "1-sigma of the line of action's offset at the reported point [m].")
      .def_property_readonly(
          "sigma_point", [](const Estimate& e) { return e.value.sigma_point; },
          "1-sigma of the surface point [m].")
      .def_property_readonly(
          "force_covariance_W",
          [](const Estimate& e) { return to_numpy(e.value.force_covariance_W); },
          "(3, 3) covariance of force_W [N^2].")
      .def_property_readonly(
          "moment_W", [](const Estimate& e) { return e.value.moment_W; },
          "(3,) pure moment M_ext [N m] (known point).")
      .def_property_readonly(
          "point_W", [](const Estimate& e) { return e.value.point_W; }, "(3,) contact point [m].")
      .def_property_readonly(
          "point_L", [](const Estimate& e) { return e.value.point_L; },
          "(3,) contact point in the link's frame [m].")
      .def_property_readonly(
          "line_point_W", [](const Estimate& e) { return e.value.line_point_W; },
          "(3,) point of the line of action nearest O_l (eq. 20) [m].")
      .def_property_readonly(
          "line_direction_W", [](const Estimate& e) { return e.value.line_direction_W; },
          "(3,) unit direction of the line of action.")
      .def_property_readonly(
          "surface_distance", [](const Estimate& e) { return e.value.surface_distance; }, "[m]")
      .def_property_readonly(
          "residual", [](const Estimate& e) { return to_numpy(e.value.residual); },
          "(n,) tau_ext estimate used for isolation.")
      .def_property_readonly("condition_number",
                             [](const Estimate& e) { return e.value.condition_number; })
      .def_property_readonly(
          "status", [](const Estimate& e) { return status_text(e.value.status); },
          "'ok', or the numerical outcome ('singular:...').")
      .def_property_readonly(
          "flags", [](const Estimate& e) { return flag_names(e.value.flags); },
          "frozenset of flag names ('contact', 'force', ...).")
      .def_property_readonly("flag_bits", [](const Estimate& e) { return e.value.flags; })
      .def("__repr__", [](const Estimate& e) {
        return "<extwrench.Estimate t=" + std::to_string(e.value.t) +
               " contact=" + (e.value.contact ? "True" : "False") +
               " flags=" + describe_flags(e.value.flags) + ">";
      });
}

}  // namespace

void bind_estimation(py::module_& m) {
  bind_estimate(m);
  py::class_<Estimator>(m, "ContactEstimator", R"(The contact estimator of the paper's Table I.

ContactEstimator(robot, config): config is a dict of the configuration schema (docs/config.md;
'robot' is then taken from `robot`) or the path of a configuration file (robot may be None).
Unknown keys and bad values raise extwrench.Error with the loader's message.)")
      .def(py::init(&make), py::arg("robot"), py::arg("config"))
      .def("__repr__",
           [](const Estimator& e) {
             return "<extwrench.ContactEstimator nq=" + std::to_string(e.nq()) +
                    " sensor=" + std::string(to_string(e.config.options.sensor.type)) +
                    " contact=" + std::string(to_string(e.config.options.contact.model)) +
                    " robot='" + e.config.robot_path.string() + "'>";
           })
      .def("reset", &reset, py::arg("t"), py::arg("q"), py::arg("dq"), py::arg("tau"),
           "Starts at time t [s]; q, dq, tau: (n,). tau is held over the first interval.")
      .def("update", &update, py::arg("t"), py::arg("q"), py::arg("dq"), py::arg("tau"),
           py::arg("reading") = py::none(),
           R"(One sample: t [s] (increasing), q, dq, tau (n,), reading: the base sensor's
[f; n] (6,) or f (3,) in the sensor frame, moment about its origin (None without a sensor).
Returns an Estimate. Bad input raises ValueError naming it; the state is then unchanged.)")
      .def(
          "request_tare",
          [](Estimator& e, int samples) {
            if (samples < 0) {
              throw py::value_error(
                  "request_tare: samples must be >= 0 (0 cancels a pending "
                  "tare), got " +
                  std::to_string(samples));
            }
            e.estimator.request_tare(samples);
          },
          py::arg("samples"),
          "Re-estimates the base sensor's bias over the next `samples` updates, which must be "
          "free of contact (docs/estimator.md); 0 cancels a pending tare.")
      .def(
          "warm_up", [](const Estimator& e) { e.estimator.warm_up(); },
          "Pages in what the first contact needs (the ray casting against the collision shapes); "
          "the constructor did it once. Call it from the loop's thread after a long idle phase "
          "(docs/estimator.md, Hard real time). Changes no estimate.")
      .def_property(
          "sensor_bias", [](const Estimator& e) { return Vector6(e.estimator.sensor_bias()); },
          [](Estimator& e, const py::handle& bias) {
            VectorX b;
            read_vector(bias, "sensor_bias", 6, b);
            e.estimator.set_sensor_bias(b);
          },
          "(6,) sensor bias [f; n] in the sensor frame.")
      .def_property_readonly(
          "thresholds",
          [](const Estimator& e) { return VectorX(e.estimator.detector().thresholds()); },
          "(n,) the detector's joint thresholds τ_thr at the last update: τ_min, plus b|q̇| and "
          "c|τ_dyn| when they follow the motion (docs/calibration.md).")
      .def_property_readonly("nq", &Estimator::nq)
      .def_property_readonly("bodies", [](const Estimator& e) { return *e.body_names; })
      .def_property_readonly(
          "sensor_type",
          [](const Estimator& e) { return std::string(to_string(e.config.options.sensor.type)); })
      .def_property_readonly("robot_path", [](const Estimator& e) { return e.config.robot_path; })
      .def_property_readonly(
          "calibration_path",
          [](const Estimator& e) -> py::object {
            if (e.config.calibration_path.empty()) return py::none();
            return py::cast(e.config.calibration_path);
          },
          "The calibration file the configuration includes (`calibration:`), or None.")
      .def(
          "config_yaml",
          [](const Estimator& e, const py::object& directory) {
            // Without a directory the robot's path stays absolute: the text may be written
            // anywhere, and a path relative to the working directory would not load there.
            return to_yaml(
                e.config, directory.is_none()
                              ? std::filesystem::path()
                              : std::filesystem::absolute(directory.cast<std::filesystem::path>()));
          },
          py::arg("directory") = py::none(),
          R"(The configuration as YAML text (docs/config.md).

directory: where the text will be written; the robot's path is then relative to it (as a
configuration file's paths are). Default: the absolute path.)")
      .def_property_readonly("last", [](const Estimator& e) {
        return Estimate{e.estimator.result(), e.body_names};
      });
  bind_batch(m);
}

}  // namespace extwrench::python
