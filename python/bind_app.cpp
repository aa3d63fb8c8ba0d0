// Whole jobs: a simulation scenario run as `extwrench simulate` runs it (app/scenario_run.hpp).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "extwrench/app/scenario_run.hpp"
#include "robot.hpp"

namespace extwrench::python {
namespace {

py::list run_scenario_py(const std::filesystem::path& scenario_path,
                         const std::filesystem::path& out_dir, bool figures,
                         const std::vector<std::filesystem::path>& package_path) {
  LoadOptions load;
  load.package_path = package_path;
  const Scenario scenario = load_scenario(scenario_path, load);
  RunOptions run;
  run.figures = figures;
  run.progress = false;
  std::vector<SeedResult> results;
  {
    py::gil_scoped_release release;
    results = run_scenario(scenario, out_dir, run);
  }
  py::list out;
  for (const SeedResult& r : results) {
    py::dict d;
    d["seed"] = r.seed;
    d["dir"] = r.dir;
    d["samples"] = r.samples;
    d["peak_condition"] = r.peak_condition;
    d["peak_time"] = r.peak_time;
    std::vector<std::string> schemes;
    for (const auto& s : r.schemes) schemes.push_back(s.name);
    d["schemes"] = schemes;
    out.append(d);
  }
  return out;
}

}  // namespace

void bind_app(py::module_& m) {
  m.def("_run_scenario", &run_scenario_py, py::arg("scenario"), py::arg("out_dir"),
        py::arg("figures") = false, py::arg("package_path") = std::vector<std::filesystem::path>{});
}

}  // namespace extwrench::python
