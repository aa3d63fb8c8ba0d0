// The contact estimator in the loop of a live MuJoCo simulation at 1 kHz (docs/mujoco.md).
//
// The paper arm's MJCF twin (models/paper_arm.xml) holds a bent pose with PD + MuJoCo's bias
// forces and swings joint 1 back and forth; a box stands in its way. Each step: mj_forward,
// the bridge turns mjData into the estimator's Sample (and the truth from mj_contactForce),
// the estimator updates, mj_Euler integrates. Every 100 ms it prints the estimate against
// MuJoCo's truth (the resultant on the contact link and its centre of pressure).
//
//   example_mujoco_estimator [path/to/robot.xml [seconds]]
#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/bridges/mujoco.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/input_file.hpp"

using namespace extwrench;

namespace {

// The robot's file with a box in the world (a second file beside the first keeps its paths).
std::string scene_with_box(const std::string& path) {
  std::string xml = read_input_file(path, "robot");
  const std::string box =
      "\n    <geom name=\"obstacle\" type=\"box\" pos=\"-0.5 -0.3 0.1\" size=\"0.05 0.05 0.25\" "
      "rgba=\"0.8 0.3 0.3 1\"/>";
  xml.insert(xml.find("<worldbody>") + std::string("<worldbody>").size(), box);
  return xml;
}

// MuJoCo's model of the same text, from memory.
mjModel* compile(const std::string& xml) {
  auto* vfs = new mjVFS;  // 2 MB of file names: not on the stack
  mj_defaultVFS(vfs);
  mj_makeEmptyFileVFS(vfs, "scene.xml", static_cast<int>(xml.size()) + 1);
  std::memcpy(vfs->filedata[0], xml.c_str(), xml.size() + 1);
  char error[1000] = "";
  mjModel* m = mj_loadXML("scene.xml", vfs, error, sizeof error);
  mj_deleteVFS(vfs);
  delete vfs;
  if (m == nullptr) std::fprintf(stderr, "MuJoCo: %s\n", error);
  return m;
}

void print_row(double t, const Model& model, std::span<const mujoco::BodyContactTruth> contacts,
               const ContactEstimate& e) {
  // The truth: the resultant over the links in contact, the point of the most loaded one.
  mujoco::BodyContactTruth truth;
  Vector3 force_W = Vector3::Zero();
  for (const auto& contact : contacts) {
    force_W += contact.force_W;
    if (truth.body < 0 || contact.force_W.norm() > truth.force_W.norm()) truth = contact;
  }
  truth.force_W = force_W;
  std::printf(
      "%6.2f | %-7s [%7.2f %7.2f %7.2f] [%6.3f %6.3f %6.3f] | %-7s [%7.2f %7.2f %7.2f] "
      "[%6.3f %6.3f %6.3f]\n",
      t, contacts.empty() ? "-" : model.bodies[truth.body].name.c_str(), truth.force_W.x(),
      truth.force_W.y(), truth.force_W.z(), truth.point_W.x(), truth.point_W.y(), truth.point_W.z(),
      e.contact ? model.bodies[e.link].name.c_str() : "-", e.force_W.x(), e.force_W.y(),
      e.force_W.z(), e.point_W.x(), e.point_W.y(), e.point_W.z());
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path =
      argc > 1 ? argv[1] : std::string(EXTWRENCH_MODELS_DIR) + "/paper_arm.xml";
  const double duration = argc > 2 ? std::atof(argv[2]) : 4.0;
  const std::string xml = scene_with_box(path);
  const RobotDescription robot = mujoco::load_mjcf_string(xml, path);
  const Model& model = robot.model;
  const int n = model.nq();

  mjModel* m = compile(xml);
  if (m == nullptr) return 1;
  m->opt.timestep = 0.001;
  m->opt.integrator = mjINT_EULER;  // mj_forward + bridge + mj_Euler = mj_step
  mjData* d = mj_makeData(m);
  d->qpos[1] = 0.7;  // a bent pose
  d->qpos[3] = -1.2;

  mujoco::MujocoBridge bridge(m, model);
  EstimatorOptions options;
  options.sensor.type = SensorType::kForceTorque;
  options.sensor.X_WS =
      model.frames[static_cast<std::size_t>(model.frame_index("sensor"))].placement;
  options.contact.model = ContactModel::kPureForce;
  options.observer_gain = VectorX::Constant(1, 100.0);
  ContactEstimator estimator(model, robot.geometry, options);

  VectorX q_desired(n);
  for (int i = 0; i < n; ++i) q_desired[i] = d->qpos[i];
  std::printf("%6s | %-7s %24s %23s | %-7s %24s %23s\n", "t[s]", "truth", "force [N] (world)",
              "point [m] (world)", "estim.", "F_hat [N] (world)", "point [m] (world)");
  double worst_us = 0.0, total_us = 0.0;
  const long steps = std::lround(duration / m->opt.timestep);
  for (long k = 0; k < steps; ++k) {
    const double t = d->time;
    q_desired[0] = 0.9 * std::sin(2.0 * M_PI * 0.25 * t);  // sweep into the box and back
    mj_forward(m, d);
    // PD + MuJoCo's bias forces (gravity, Coriolis); gains scaled by the joint's inertia
    // (diagonal of M), 10 rad/s critically damped: stable at 1 kHz on the light wrist too.
    constexpr double kOmega = 10.0;
    for (int i = 0; i < n; ++i) {
      const double inertia = d->qM[m->dof_Madr[i]];
      d->ctrl[i] = d->qfrc_bias[i] + inertia * (kOmega * kOmega * (q_desired[i] - d->qpos[i]) -
                                                2.0 * kOmega * d->qvel[i]);
    }
    mj_forward(m, d);  // the actuator forces of this control
    bridge.step(d);
    const Sample& s = bridge.sample();
    const auto start = std::chrono::steady_clock::now();
    const Status status = k == 0 ? estimator.reset(s) : estimator.update(s);
    const double us =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    worst_us = std::max(worst_us, us);
    total_us += us;
    if (!status.ok()) {
      std::printf("estimator: %s\n", std::string(to_string(status.code)).c_str());
      return 1;
    }
    if (k % 100 == 0) print_row(t, model, bridge.contacts(), estimator.result());
    mj_Euler(m, d);
  }
  std::printf("estimator update: mean %.2f us, worst %.2f us over %ld steps\n",
              total_us / static_cast<double>(steps), worst_us, steps);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
