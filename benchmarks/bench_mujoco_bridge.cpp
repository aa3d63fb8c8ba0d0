// The MuJoCo bridge's per-step cost (docs/mujoco.md "The bridge"): MujocoBridge::step on the
// paper arm's MJCF twin resting on a box (contacts on several links: the per-link truth, its
// Jacobians and names are computed) and free of contacts; mj_forward of the same scene for
// scale. Issue 13 asks the bridge to add at most 1 µs to the estimator's update.
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <cstring>
#include <memory>
#include <string>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/bridges/mujoco.hpp"
#include "extwrench/io/input_file.hpp"
#include "robots.hpp"

namespace extwrench::bench {
namespace {

struct Scene {
  RobotDescription robot;
  mjModel* m = nullptr;
  mjData* d = nullptr;
  Scene(bool with_box, int settle_steps) {
    std::string xml =
        read_input_file(std::string(EXTWRENCH_SOURCE_DIR) + "/models/paper_arm.xml", "robot");
    if (with_box) {
      xml.insert(xml.find("<worldbody>") + std::string("<worldbody>").size(),
                 "<geom type=\"box\" pos=\"0.5 0 0.3\" size=\"0.2 0.6 0.3\"/>"
                 "<geom type=\"box\" pos=\"-0.5 0 0.3\" size=\"0.2 0.6 0.3\"/>"
                 "<geom type=\"box\" pos=\"0 0.5 0.3\" size=\"0.3 0.2 0.3\"/>"
                 "<geom type=\"box\" pos=\"0 -0.5 0.3\" size=\"0.3 0.2 0.3\"/>");
    }
    robot = mujoco::load_mjcf_string(xml, "paper_arm.xml");
    const auto vfs = std::make_unique<mjVFS>();  // 2 MB of file names: not on the stack
    mj_defaultVFS(vfs.get());
    mj_makeEmptyFileVFS(vfs.get(), "scene.xml", static_cast<int>(xml.size()) + 1);
    std::memcpy(vfs->filedata[0], xml.c_str(), xml.size() + 1);
    char error[1000] = "";
    m = mj_loadXML("scene.xml", vfs.get(), error, sizeof error);
    mj_deleteVFS(vfs.get());
    m->opt.integrator = mjINT_EULER;
    d = mj_makeData(m);
    d->qpos[1] = 0.6;  // falls onto the boxes (the scene of tests/reference/test_mujoco_bridge)
    d->qpos[3] = -0.8;
    for (int k = 0; k < settle_steps; ++k) mj_step(m, d);
    mj_forward(m, d);
  }
  ~Scene() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
};

void BM_MujocoBridge_Step(benchmark::State& state) {
  static Scene scene(true, 1000);
  mujoco::MujocoBridge bridge(scene.m, scene.robot.model);
  bridge.step(scene.d);
  state.counters["contact_links"] = static_cast<double>(bridge.contacts().size());
  state.counters["mj_contacts"] = scene.d->ncon;
  auto call = [&](int) {
    bridge.step(scene.d);
    benchmark::DoNotOptimize(bridge.sample().q.data());
  };
  for (auto _ : state) call(0);
  state.counters["allocs"] = allocations_per_call(call);
}
BENCHMARK(BM_MujocoBridge_Step);

void BM_MujocoBridge_StepFree(benchmark::State& state) {
  static Scene scene(false, 0);
  mujoco::MujocoBridge bridge(scene.m, scene.robot.model);
  auto call = [&](int) {
    bridge.step(scene.d);
    benchmark::DoNotOptimize(bridge.sample().q.data());
  };
  for (auto _ : state) call(0);
  state.counters["allocs"] = allocations_per_call(call);
}
BENCHMARK(BM_MujocoBridge_StepFree);

// For scale: MuJoCo's own forward pass on the scene with contacts.
void BM_MujocoForward(benchmark::State& state) {
  static Scene scene(true, 1000);
  for (auto _ : state) mj_forward(scene.m, scene.d);
}
BENCHMARK(BM_MujocoForward);

}  // namespace
}  // namespace extwrench::bench
