#include <array>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "commands.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench::cli {

Pose parse_pose(const std::string& text, const std::string& option) {
  const auto fail = [&](const std::string& why) -> UsageError {
    return UsageError(option + ": " + why + " in '" + text +
                      "'; expected six numbers \"x y z roll pitch yaw\" (metres, radians), "
                      "e.g. --sensor-pose \"0 0 0.1 0 0 1.5708\"");
  };
  std::array<double, 6> values{};
  std::size_t count = 0;
  std::string token;
  const auto take = [&]() {
    if (token.empty()) return;
    if (count == values.size()) throw fail("more than six numbers");
    const auto value = parse_number(token);
    if (!value) throw fail("'" + token + "' is not a finite number");
    values[count++] = *value;
    token.clear();
  };
  for (const char c : text) {
    if (c == ' ' || c == '\t' || c == ',') {
      take();
    } else {
      token.push_back(c);
    }
  }
  take();
  if (count != values.size()) throw fail(std::to_string(count) + " number(s)");
  return Pose::from_xyz_rpy(Vector3(values[0], values[1], values[2]),
                            Vector3(values[3], values[4], values[5]));
}

void add_package_path_option(CLI::App& sub, std::vector<std::filesystem::path>& dirs) {
  sub.add_option("--package-path", dirs,
                 "Directory searched for package://NAME/... mesh URIs (NAME is a subdirectory); "
                 "repeatable; ROS_PACKAGE_PATH is searched after these")
      ->type_name("DIR");
}

RobotDescription load_robot_file(const std::filesystem::path& path,
                                 const std::vector<std::filesystem::path>& package_path) {
  check_input_file(path, "robot", kMaxTextFileBytes);
  LoadOptions options;
  options.package_path = package_path;
  return load_robot(path, options);
}

Pose default_sensor_pose(const Model& model, std::string* description) {
  const auto frame = model.find_frame("sensor");
  if (!frame) {
    if (description)
      *description = "the root link's origin ('" + model.bodies[0].name + "'), aligned with it";
  } else {
    const Frame& f = model.frames[static_cast<std::size_t>(*frame)];
    if (f.body != 0) {
      throw Error("frame 'sensor' is attached to the moving body '" +
                  model.bodies[static_cast<std::size_t>(f.body)].name +
                  "', but a base sensor must be fixed to link 0; give --sensor-pose instead");
    }
    if (description) *description = "the model's frame 'sensor'";
  }
  return extwrench::default_sensor_pose(model);  // the library's rule (estimation/base_sensor)
}

std::string fmt(double value) {
  if (value == 0.0) return "0";  // also turns -0 into 0
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), "%.10g", value);
  return text.data();
}

std::string fmt(const Vector3& v) {
  return "(" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + ")";
}

}  // namespace extwrench::cli
