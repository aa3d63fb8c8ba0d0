// load_mjcf: MuJoCo's own compiler reads the file (includes, defaults, meshes); its warnings are
// kept out of MUJOCO_LOG.TXT while it does, and its errors become extwrench::Error.
#include <mujoco/mujoco.h>

#include <memory>
#include <mutex>

#include "extwrench/bridges/mjcf.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"

namespace extwrench::mujoco {

namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};

// MuJoCo's message with its line breaks ("Error: ...\nElement 'geom', line 14\n") on one line.
std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (char& c : text) {
    if (c == '\n') c = ' ';
  }
  return text;
}

// The warning handler is global in MuJoCo: one load at a time swaps it.
std::mutex g_load_mutex;
void ignore_warning(const char* /*message*/) {}

std::unique_ptr<mjModel, ModelDeleter> compile(const std::filesystem::path& path) {
  const std::lock_guard<std::mutex> lock(g_load_mutex);
  void (*previous)(const char*) = mju_user_warning;
  mju_user_warning = ignore_warning;
  char error[2048] = "";
  std::unique_ptr<mjModel, ModelDeleter> m(
      mj_loadXML(path.string().c_str(), nullptr, error, sizeof error));
  mju_user_warning = previous;
  if (!m) throw Error(path.string() + ": MuJoCo rejects the MJCF: " + one_line(error));
  return m;
}

}  // namespace

RobotDescription load_mjcf(const std::filesystem::path& path, const LoadOptions& options) {
  check_input_file(path, "robot", kMaxTextFileBytes);
  const auto m = compile(path);
  RobotDescription robot = robot_from_mjmodel(m.get(), path.string(), options);
  robot.source = path;
  return robot;
}

void register_mjcf_loader() noexcept { set_mjcf_loader(&load_mjcf); }

}  // namespace extwrench::mujoco
