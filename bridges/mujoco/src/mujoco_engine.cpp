// `engine: mujoco`: a scenario's closed loop in MuJoCo (docs/simulation.md "The MuJoCo engine").
#include "extwrench/bridges/mujoco_engine.hpp"

#include <mujoco/mujoco.h>
#include <tinyxml2.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/sim/force_profile.hpp"
#include "mjcf_detail.hpp"

namespace extwrench::mujoco {
namespace {

std::string numbers(std::initializer_list<double> values) {
  std::string out;
  for (const double v : values) {
    if (!out.empty()) out += ' ';
    out += format_number(v);
  }
  return out;
}

// pos="..." quat="..." of a pose (MuJoCo's quaternion: w x y z).
std::string pose_attributes(const Pose& X) {
  const Eigen::Quaterniond q(X.rotation);
  return "pos=\"" + numbers({X.translation.x(), X.translation.y(), X.translation.z()}) +
         "\" quat=\"" + numbers({q.w(), q.x(), q.y(), q.z()}) + "\"";
}

std::string obstacle_geom(const Obstacle& o, bool in_body) {
  std::string size;
  const char* type = "box";
  switch (o.shape) {
    case Obstacle::Shape::kBox:  // MuJoCo: half sides
      size = numbers({o.size.x() / 2, o.size.y() / 2, o.size.z() / 2});
      break;
    case Obstacle::Shape::kSphere:
      type = "sphere";
      size = numbers({o.size.x()});
      break;
    case Obstacle::Shape::kCapsule:  // MuJoCo: radius, half-length of the cylinder
      type = "capsule";
      size = numbers({o.size.x(), o.size.y() / 2});
      break;
  }
  const VectorX& si = o.solimp;
  // priority 1: MuJoCo takes the obstacle's friction, solref and solimp for its contacts with
  // the robot (instead of mixing them with the robot geom's).
  return std::string("<geom name=\"") + kSceneObstaclePrefix + o.name + "\" type=\"" + type +
         "\" size=\"" + size + "\" " + (in_body ? "" : "POSE ") +
         "contype=\"1\" conaffinity=\"1\" " + "priority=\"1\" condim=\"" +
         std::to_string(o.condim) + "\" friction=\"" +
         numbers({o.friction.x(), o.friction.y(), o.friction.z()}) + "\" solref=\"" +
         numbers({o.solref.x(), o.solref.y()}) + "\" solimp=\"" +
         numbers({si[0], si[1], si[2], si[3], si[4]}) + "\" rgba=\"0.8 0.35 0.3 1\"/>";
}

// MuJoCo's model of the scene text, compiled as if it were a file in the robot's directory
// (its meshes and includes resolve as the robot file's own).
mjModel* compile(const std::string& xml, const std::filesystem::path& robot_path,
                 const std::string& label) {
  auto* vfs = new mjVFS;  // large: not on the stack
  mj_defaultVFS(vfs);
  const std::filesystem::path name = std::filesystem::absolute(robot_path).parent_path() /
                                     (robot_path.stem().string() + ".extwrench_scene.xml");
  mjModel* m = nullptr;
  char error[1000] = "";
  if (mj_makeEmptyFileVFS(vfs, name.string().c_str(), static_cast<int>(xml.size()) + 1) == 0) {
    std::memcpy(vfs->filedata[vfs->nfile - 1], xml.c_str(), xml.size() + 1);
    m = mj_loadXML(name.string().c_str(), vfs, error, sizeof error);
  } else {
    std::snprintf(error, sizeof error, "the virtual file system is full");
  }
  mj_deleteVFS(vfs);
  delete vfs;
  if (m == nullptr) throw Error(label + ": MuJoCo rejects the scene: " + error);
  return m;
}

// The compiled model has the options the scenario asked for (no later <option> overrode them).
void check_option(const mjModel* m, const MujocoOption& option, const std::string& label) {
  const auto fail = [&](const std::string& what) {
    throw Error(label + ": mujoco_option." + what +
                " did not reach the compiled model (an <option> MuJoCo read after it?)");
  };
  if (option.cone) {
    const int cone =
        *option.cone == MujocoOption::Cone::kElliptic ? mjCONE_ELLIPTIC : mjCONE_PYRAMIDAL;
    if (m->opt.cone != cone) fail("cone");
  }
  if (option.impratio && m->opt.impratio != *option.impratio) fail("impratio");
}

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};

// The root body's pose in MuJoCo's world (the root is welded: any q gives the same).
Pose root_pose(const mjModel* m, int root) {
  Pose X;
  if (root <= 0) return X;
  mjData* d = mj_makeData(m);
  mj_kinematics(m, d);
  for (int i = 0; i < 3; ++i) {
    X.translation[i] = d->xpos[3 * root + i];
    for (int j = 0; j < 3; ++j) X.rotation(i, j) = d->xmat[9 * root + 3 * i + j];
  }
  mj_deleteData(d);
  return X;
}

std::string robot_label(const Scenario& s) {
  return s.source.string() + ": robot '" + s.robot_path.string() + "'";
}

}  // namespace

namespace {

// `text` (one element, e.g. "<site .../>") parsed and copied into `doc`.
tinyxml2::XMLNode* element(tinyxml2::XMLDocument& doc, const std::string& text) {
  tinyxml2::XMLDocument snippet;
  if (snippet.Parse(text.c_str()) != tinyxml2::XML_SUCCESS || snippet.RootElement() == nullptr)
    throw Error("scene_mjcf: internal MJCF snippet does not parse: " + text);
  return snippet.RootElement()->DeepClone(&doc);
}

// The <body name="NAME"> below `parent` (depth first), or nullptr.
tinyxml2::XMLElement* find_body(tinyxml2::XMLElement* parent, const std::string& name) {
  for (tinyxml2::XMLElement* b = parent->FirstChildElement("body"); b != nullptr;
       b = b->NextSiblingElement("body")) {
    const char* n = b->Attribute("name");
    if (n != nullptr && name == n) return b;
    if (tinyxml2::XMLElement* found = find_body(b, name)) return found;
  }
  return nullptr;
}

}  // namespace

std::string scene_mjcf(const Scenario& s, const Pose& X_WS, const Pose& X_mj_root,
                       const std::vector<std::string>& robot_bodies) {
  const std::string text = read_input_file(s.robot_path, "robot");
  const std::string label = robot_label(s);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.c_str()) != tinyxml2::XML_SUCCESS) {
    throw Error(label + ":" + std::to_string(doc.ErrorLineNum()) + ": not XML: " + doc.ErrorStr());
  }
  tinyxml2::XMLElement* mujoco = doc.RootElement();
  if (mujoco == nullptr || std::strcmp(mujoco->Name(), "mujoco") != 0) {
    throw Error(label + ": engine: mujoco needs an MJCF robot (root element <mujoco>)");
  }
  tinyxml2::XMLElement* worldbody = mujoco->FirstChildElement("worldbody");
  if (worldbody == nullptr) throw Error(label + ": no <worldbody> in the file's own text");
  // The base sensor: a site at X_WS on the root body (W is the root's frame) with a <force>
  // and a <torque> sensor.
  const std::string site = std::string("<site name=\"") + kSceneSensorSite + "\" " +
                           pose_attributes(X_WS) + " size=\"0.005\"/>";
  const std::string& root = s.robot.model.bodies[0].name;
  tinyxml2::XMLElement* root_body = nullptr;
  for (tinyxml2::XMLElement* w = worldbody; w != nullptr && root_body == nullptr;
       w = w->NextSiblingElement("worldbody"))
    root_body = find_body(w, root);
  if (root_body != nullptr) {
    root_body->InsertFirstChild(element(doc, site));
  } else if (root == "world") {
    worldbody->InsertFirstChild(element(doc, site));
  } else {
    throw Error(label + ": the root body '" + root +
                "' is not in the file's own text (in an <include>d file?): engine: mujoco adds "
                "the base sensor to it");
  }
  // The obstacles, first in the world body, in their order.
  tinyxml2::XMLNode* previous = nullptr;
  for (const Obstacle& o : s.obstacles) {
    const Pose X = X_mj_root * o.pose;
    std::string obstacle;
    if (o.motion == Obstacle::Motion::kFixed) {
      obstacle = obstacle_geom(o, false);
      obstacle.replace(obstacle.find("POSE"), 4, pose_attributes(X));
    } else {
      obstacle = "<body name=\"" + std::string(kSceneObstaclePrefix) + o.name +
                 "\" mocap=\"true\" " + pose_attributes(X) + ">" + obstacle_geom(o, true) +
                 "</body>";
    }
    tinyxml2::XMLNode* node = element(doc, obstacle);
    previous = previous == nullptr ? worldbody->InsertFirstChild(node)
                                   : worldbody->InsertAfterChild(previous, node);
  }
  // No self-collisions: a contact between two links of the robot is internal (no external
  // wrench, not in the truth) but acts on the joints between them.
  if (robot_bodies.size() > 1) {
    tinyxml2::XMLElement* contact = doc.NewElement("contact");
    for (std::size_t a = 0; a < robot_bodies.size(); ++a) {
      for (std::size_t b = a + 1; b < robot_bodies.size(); ++b) {
        tinyxml2::XMLElement* exclude = contact->InsertNewChildElement("exclude");
        exclude->SetAttribute("body1", robot_bodies[a].c_str());
        exclude->SetAttribute("body2", robot_bodies[b].c_str());
      }
    }
    mujoco->InsertEndChild(contact);
  }
  // mujoco_option: an <option> of its own, last in the file, carrying only the attributes set.
  // MuJoCo merges every <option> attribute by attribute, the last one winning: the file's other
  // values stay, and an <option> in an <include>d file (which the file's own text does not show)
  // cannot override it, as it did when this edited the first <option> of the text.
  const MujocoOption& option = s.mujoco_option;
  if (option.cone || option.impratio) {
    tinyxml2::XMLElement* opt = doc.NewElement("option");
    if (option.cone)
      opt->SetAttribute("cone",
                        *option.cone == MujocoOption::Cone::kElliptic ? "elliptic" : "pyramidal");
    if (option.impratio) opt->SetAttribute("impratio", numbers({*option.impratio}).c_str());
    mujoco->InsertEndChild(opt);
  }
  tinyxml2::XMLElement* sensor = doc.NewElement("sensor");
  for (const auto& [type, name] :
       {std::pair{"force", kSceneForceSensor}, std::pair{"torque", kSceneTorqueSensor}}) {
    tinyxml2::XMLElement* e = sensor->InsertNewChildElement(type);
    e->SetAttribute("name", name);
    e->SetAttribute("site", kSceneSensorSite);
  }
  mujoco->InsertEndChild(sensor);
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

MujocoSimulator::MujocoSimulator(const Scenario& s, sim::ComputedTorqueController controller,
                                 sim::SimulationConfig config)
    : model_(s.robot.model),
      controller_(std::move(controller)),
      config_(std::move(config)),
      obstacles_(s.obstacles),
      joint_sensor_(config_.encoder, model_.nq()),
      noise_(config_.noise_seed),
      data_(model_) {
  const int n = model_.nq();
  const std::string label = robot_label(s);
  if (controller_.model().nq() != n) throw Error(label + ": the controller's model differs");
  if (!(config_.sample_time > 0.0) || config_.substeps < 1)
    throw Error(s.source.string() + ": sample_time and substeps must be positive");
  // The root's pose and the robot's bodies first (the scene without obstacles), then the scene.
  std::vector<std::string> robot_bodies;
  {
    Scenario robot_only = s;
    robot_only.obstacles.clear();
    const std::unique_ptr<mjModel, ModelDeleter> robot(compile(
        scene_mjcf(robot_only, config_.sensor.X_WS, Pose::identity()), s.robot_path, label));
    X_mj_root_ =
        root_pose(robot.get(), mj_name2id(robot.get(), mjOBJ_BODY, model_.bodies[0].name.c_str()));
    for (int b = 1; b < robot->nbody; ++b) {
      const char* name = mj_id2name(robot.get(), mjOBJ_BODY, b);
      if (name != nullptr && model_.find_frame(name)) robot_bodies.emplace_back(name);
    }
  }
  scene_ = scene_mjcf(s, config_.sensor.X_WS, X_mj_root_, robot_bodies);
  m_ = compile(scene_, s.robot_path, label);
  check_option(m_, s.mujoco_option, label);
  m_->opt.timestep = config_.sample_time / config_.substeps;
  d_ = mj_makeData(m_);
  BridgeOptions bridge_options;
  bridge_options.force_sensor = kSceneForceSensor;
  bridge_options.torque_sensor = kSceneTorqueSensor;
  bridge_ = std::make_unique<MujocoBridge>(m_, model_, bridge_options);
  for (int i = 1; i <= n; ++i) {
    const int j =
        mj_name2id(m_, mjOBJ_JOINT, model_.joints[static_cast<std::size_t>(i)].name.c_str());
    qpos_adr_.push_back(m_->jnt_qposadr[j]);
    dof_adr_.push_back(m_->jnt_dofadr[j]);
  }
  for (const Obstacle& o : obstacles_) {
    const int b = mj_name2id(m_, mjOBJ_BODY, (kSceneObstaclePrefix + o.name).c_str());
    mocap_of_obstacle_.push_back(b > 0 ? m_->body_mocapid[b] : -1);
  }
  mj_body_of_body_.assign(model_.bodies.size(), -1);
  for (int b = 0; b < m_->nbody; ++b) {
    const char* name = mj_id2name(m_, mjOBJ_BODY, b);
    const auto frame = name != nullptr ? model_.find_frame(name) : std::nullopt;
    if (!frame) continue;
    int& mine = mj_body_of_body_[static_cast<std::size_t>(
        model_.frames[static_cast<std::size_t>(*frame)].body)];
    if (mine < 0) mine = b;
  }
  for (sim::ForceProfile& f : config_.forces) {
    f.resolve(model_);
    if (mj_body_of_body_[static_cast<std::size_t>(f.body)] < 0)
      throw Error(label + ": force on frame '" + f.frame + "': no MuJoCo body of its link");
  }
  wrenches_.reserve(config_.forces.size() + 1);

  // Initial state: q_d(0), q̇_d(0) (or config.q0, dq0), every other joint at MuJoCo's qpos0.
  q_.setZero(n);
  dq_.setZero(n);
  VectorX ddq(n);
  controller_.trajectory().evaluate(0.0, q_, dq_, ddq);
  if (config_.q0.size() == n) q_ = config_.q0;
  if (config_.dq0.size() == n) dq_ = config_.dq0;
  for (int i = 0; i < n; ++i) {
    d_->qpos[qpos_adr_[static_cast<std::size_t>(i)]] = q_[i];
    d_->qvel[dof_adr_[static_cast<std::size_t>(i)]] = dq_[i];
  }
  qm_.setZero(n);
  dqm_.setZero(n);
  num_samples_ = static_cast<long>(std::floor(config_.duration / config_.sample_time + 1e-9)) + 1;
  controller_.reset(0.0);
  place_obstacles(0.0);
}

MujocoSimulator::~MujocoSimulator() {
  bridge_.reset();
  if (d_ != nullptr) mj_deleteData(d_);
  if (m_ != nullptr) mj_deleteModel(m_);
}

void MujocoSimulator::place_obstacles(double t) noexcept {
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const int id = mocap_of_obstacle_[i];
    if (id < 0) continue;
    const Vector3 p = X_mj_root_.rotation * obstacles_[i].position(t) + X_mj_root_.translation;
    for (int r = 0; r < 3; ++r) d_->mocap_pos[3 * id + r] = p[r];
  }
}

// The scenario's forces at t as xfrc_applied: [force; torque about the body's CoM], MuJoCo's
// world axes.
void MujocoSimulator::apply_forces(double t, const VectorX& q) {
  mju_zero(d_->xfrc_applied, 6 * m_->nbody);
  if (config_.forces.empty()) return;
  mj_kinematics(m_, d_);  // xipos: the bodies' CoMs
  forward_kinematics(model_, data_, q);
  sim::evaluate_forces(config_.forces, t, data_, wrenches_);
  const Matrix3& R = X_mj_root_.rotation;
  for (const ExternalWrench& w : wrenches_) {
    const int b = mj_body_of_body_[static_cast<std::size_t>(w.body)];
    const Vector3 f = R * w.force_W;
    const Vector3 p = R * w.point_W + X_mj_root_.translation;
    const Vector3 com(d_->xipos[3 * b], d_->xipos[3 * b + 1], d_->xipos[3 * b + 2]);
    const Vector3 torque = (p - com).cross(f) + R * w.moment_W;
    for (int r = 0; r < 3; ++r) {
      d_->xfrc_applied[6 * b + r] += f[r];
      d_->xfrc_applied[6 * b + 3 + r] += torque[r];
    }
  }
}

bool MujocoSimulator::next(Sample& out) {
  if (k_ >= num_samples_) return false;
  const int n = model_.nq();
  const double t = sim::sample_instant(k_, config_.sample_time);
  for (int i = 0; i < n; ++i) {
    q_[i] = d_->qpos[qpos_adr_[static_cast<std::size_t>(i)]];
    dq_[i] = d_->qvel[dof_adr_[static_cast<std::size_t>(i)]];
  }
  joint_sensor_.measure(t, q_, dq_, qm_, dqm_);
  const VectorX& tau = controller_.update(t, qm_, dqm_);
  for (int i = 0; i < n; ++i) d_->qfrc_applied[dof_adr_[static_cast<std::size_t>(i)]] = tau[i];
  apply_forces(t, q_);
  mj_forward(m_, d_);
  bridge_->step(d_);
  const Sample& s = bridge_->sample();
  out.t = t;
  out.q = qm_;
  out.dq = dqm_;
  out.tau = s.tau;
  config_.sensor.write_reading(s.reading_S, noise_, out);
  out.has_truth = true;
  out.has_true_tau_ext = true;
  out.truth = s.truth;

  // To t_{k+1}: the first step reuses this mj_forward, the others are whole mj_steps; moving
  // obstacles follow their motion at every step.
  const double h = m_->opt.timestep;
  for (int sub = 0; sub < config_.substeps; ++sub) {
    if (sub == 0) {
      if (m_->opt.integrator == mjINT_EULER) {
        mj_Euler(m_, d_);
      } else if (m_->opt.integrator == mjINT_RK4) {
        mj_RungeKutta(m_, d_, 4);
      } else {
        mj_step2(m_, d_);  // implicit: recomputes the accelerations, then integrates
      }
    } else {
      place_obstacles(t + sub * h);
      mj_step(m_, d_);
    }
  }
  place_obstacles(t + config_.sample_time);
  for (int i = 0; i < m_->nq; ++i) {
    if (!std::isfinite(d_->qpos[i])) {
      throw Error("MuJoCo engine: the state diverged near t = " + std::to_string(t) +
                  " (reduce the step, the gains or the contact stiffness)");
    }
  }
  if (d_->warning[mjWARN_BADQACC].number > 0) {
    throw Error("MuJoCo engine: bad acceleration near t = " + std::to_string(t) +
                " (MuJoCo reset the simulation)");
  }
  ++k_;
  return true;
}

namespace {
std::unique_ptr<sim::SampleSource> make_engine(const Scenario& scenario,
                                               sim::ComputedTorqueController controller,
                                               const sim::SimulationConfig& config) {
  return std::make_unique<MujocoSimulator>(scenario, std::move(controller), config);
}
}  // namespace

void register_mujoco_engine() noexcept { set_mujoco_engine(&make_engine); }

}  // namespace extwrench::mujoco
