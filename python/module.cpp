// The compiled part of the `extwrench` Python package (python/extwrench/__init__.py wraps it).
#include <pybind11/pybind11.h>

#include "extwrench/core/error.hpp"
#include "robot.hpp"

#ifdef EXTWRENCH_HAVE_MUJOCO
#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/bridges/mujoco_engine.hpp"
#endif

#ifndef EXTWRENCH_VERSION
#error "EXTWRENCH_VERSION must be defined by the build (the project's version)"
#endif

PYBIND11_MODULE(_extwrench, m) {
  namespace py = pybind11;
  namespace ew = extwrench::python;
  m.doc() = "extwrench: external wrench estimation (compiled core; import extwrench instead)";
  m.attr("__version__") = EXTWRENCH_VERSION;
  // The library's set-up errors keep their message (file:line: key: what). A ValueError: they
  // are bad input (files, configurations) more than failures of the program.
  py::register_exception<extwrench::Error>(m, "Error", PyExc_ValueError);
#ifdef EXTWRENCH_HAVE_MUJOCO
  extwrench::mujoco::register_mjcf_loader();    // load_robot reads MJCF, as the CLI does
  extwrench::mujoco::register_mujoco_engine();  // simulate() runs engine: mujoco scenarios
#endif
  ew::bind_model(m);
  ew::bind_dynamics(m);
  ew::bind_estimation(m);
  ew::bind_io(m);
  ew::bind_app(m);
  ew::bind_bench(m);
}
