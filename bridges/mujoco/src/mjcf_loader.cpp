// load_mjcf: MuJoCo's own compiler reads the file (includes, defaults, meshes); its warnings are
// kept out of MUJOCO_LOG.TXT while it does, and its errors become extwrench::Error.
#include <mujoco/mujoco.h>

#include <cstring>
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

// MuJoCo's error, and for a word its schema does not know the likely cause: a file written for a
// newer MuJoCo (the MuJoCo Menagerie's current Panda: integrator="implicitfast", `kv`).
std::string rejection(const std::string& name, const char* error) {
  std::string text = name + ": MuJoCo rejects the MJCF: " + one_line(error);
  if (std::strstr(error, "invalid keyword") != nullptr ||
      std::strstr(error, "unrecognized attribute") != nullptr ||
      std::strstr(error, "unrecognized element") != nullptr) {
    text += std::string(" (this MuJoCo is ") + mj_versionString() +
            ": a file written for a newer one can use words it does not know; replace them, "
            "e.g. integrator=\"implicitfast\" by \"implicit\" (docs/mujoco.md))";
  }
  return text;
}

// The warning handler is global in MuJoCo: one load at a time swaps it.
std::mutex g_load_mutex;
void ignore_warning(const char* /*message*/) {}

// Compiles `path` (a file, or the one file of `vfs`); `name` prefixes the errors.
std::unique_ptr<mjModel, ModelDeleter> compile(const std::string& path, const mjVFS* vfs,
                                               const std::string& name) {
  const std::lock_guard<std::mutex> lock(g_load_mutex);
  void (*previous)(const char*) = mju_user_warning;
  mju_user_warning = ignore_warning;
  char error[2048] = "";
  std::unique_ptr<mjModel, ModelDeleter> m(mj_loadXML(path.c_str(), vfs, error, sizeof error));
  mju_user_warning = previous;
  if (!m) throw Error(rejection(name, error));
  return m;
}

}  // namespace

RobotDescription load_mjcf(const std::filesystem::path& path, const LoadOptions& options) {
  check_input_file(path, "robot", kMaxTextFileBytes);
  const auto m = compile(path.string(), nullptr, path.string());
  RobotDescription robot = robot_from_mjmodel(m.get(), path.string(), options);
  robot.source = path;
  return robot;
}

RobotDescription load_mjcf_string(const std::string& xml, const std::string& name,
                                  const LoadOptions& options) {
  constexpr const char* kVfsName = "robot.xml";
  struct VfsDeleter {
    void operator()(mjVFS* vfs) const {
      mj_deleteVFS(vfs);
      delete vfs;
    }
  };
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);  // large (2000 file names): not on the stack
  mj_defaultVFS(vfs.get());
  if (xml.size() > kMaxTextFileBytes ||
      mj_makeEmptyFileVFS(vfs.get(), kVfsName, static_cast<int>(xml.size()) + 1) != 0) {
    throw Error(name + ": the MJCF text is too large");
  }
  std::memcpy(vfs->filedata[0], xml.c_str(), xml.size() + 1);
  const auto m = compile(kVfsName, vfs.get(), name);
  RobotDescription robot = robot_from_mjmodel(m.get(), name, options);
  robot.source = name;
  return robot;
}

void register_mjcf_loader() noexcept { set_mjcf_loader(&load_mjcf); }

}  // namespace extwrench::mujoco
