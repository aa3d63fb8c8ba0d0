#include <array>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "commands.hpp"
#include "extwrench/app/jobs.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/input_file.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/output_files.hpp"

namespace extwrench::cli {

std::vector<double> parse_numbers(const std::string& text, std::size_t most, const char* most_words,
                                  const std::function<UsageError(const std::string&)>& fail) {
  std::vector<double> values;
  std::string token;
  const auto take = [&]() {
    if (token.empty()) return;
    if (values.size() == most) throw fail(std::string("more than ") + most_words + " numbers");
    const auto value = parse_number(token);
    if (!value) throw fail("'" + token + "' is not a finite number");
    values.push_back(*value);
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
  return values;
}

Pose parse_pose(const std::string& text, const std::string& option) {
  const auto fail = [&](const std::string& why) -> UsageError {
    return UsageError(option + ": " + why + " in '" + text +
                      "'; expected six numbers \"x y z roll pitch yaw\" (metres, radians), "
                      "e.g. --sensor-pose \"0 0 0.1 0 0 1.5708\"");
  };
  const std::vector<double> values = parse_numbers(text, 6, "six", fail);
  if (values.size() != 6) throw fail(std::to_string(values.size()) + " number(s)");
  return Pose::from_xyz_rpy(Vector3(values[0], values[1], values[2]),
                            Vector3(values[3], values[4], values[5]));
}

void add_package_path_option(CLI::App& sub, std::vector<std::filesystem::path>& dirs) {
  sub.add_option("--package-path", dirs,
                 "Directory searched for package://NAME/... mesh URIs (NAME is a subdirectory); "
                 "repeatable; ROS_PACKAGE_PATH is searched after these")
      ->type_name("DIR");
}

void add_lock_option(CLI::App& sub, std::vector<std::string>& locks) {
  sub.add_option("--lock", locks,
                 "Hold joint NAME fixed at VALUE [rad | m] (repeatable): a tree's extra branches "
                 "(e.g. a gripper's fingers) merge into their parent link, leaving a serial chain")
      ->type_name("NAME=VALUE");
}

void add_chain_options(CLI::App& sub, std::string& root_body, std::string& tip_body) {
  sub.add_option("--root-body", root_body,
                 "MJCF only: the body that becomes link 0 (for a scene with several bodies)")
      ->type_name("BODY");
  sub.add_option("--tip-body", tip_body,
                 "MJCF only: keep only the chain from the root body to BODY")
      ->type_name("BODY");
}

LoadOptions robot_load_options(const std::vector<std::filesystem::path>& package_path,
                               const std::vector<std::string>& locks, const std::string& root_body,
                               const std::string& tip_body) {
  LoadOptions options;
  options.package_path = package_path;
  options.root_body = root_body;
  options.tip_body = tip_body;
  for (const std::string& text : locks) {
    const auto eq = text.find('=');
    const auto value = eq == std::string::npos ? std::nullopt : parse_number(text.substr(eq + 1));
    if (eq == std::string::npos || eq == 0 || !value) {
      throw UsageError("--lock: expected NAME=VALUE with VALUE a finite number [rad | m], got '" +
                       text + "', e.g. --lock panda_finger_joint1=0.02");
    }
    const std::string name = text.substr(0, eq);
    if (!options.locked_joints.emplace(name, *value).second)
      throw UsageError("--lock: joint '" + name + "' is locked twice");
    options.locked_joint_sources[name] = "--lock " + text;
  }
  return options;
}

RobotDescription load_robot_file(const std::filesystem::path& path, const LoadOptions& options) {
  check_input_file(path, "robot", kMaxTextFileBytes);
  return load_robot(path, options);
}

Pose default_sensor_pose(const Model& model, std::string* description) {
  const auto frame = model.find_frame("sensor");
  if (frame && model.frames[static_cast<std::size_t>(*frame)].body != 0) {
    throw Error(
        "frame 'sensor' is attached to the moving body '" +
        model.bodies[static_cast<std::size_t>(model.frames[static_cast<std::size_t>(*frame)].body)]
            .name +
        "', but a base sensor must be fixed to link 0; give --sensor-pose instead");
  }
  if (description) *description = describe_default_sensor_pose(model);
  return extwrench::default_sensor_pose(model);  // the library's rule (estimation/base_sensor)
}

std::string pose_summary(const Pose& X) {
  return "xyz " + fmt(X.translation) + " m, rpy " + fmt(rpy_from_rotation(X.rotation)) + " rad";
}

void check_output_file(const std::filesystem::path& out, const std::string& option,
                       std::initializer_list<std::filesystem::path> inputs) {
  try {
    OutputFiles::check_file_target(out);
  } catch (const Error& e) {
    throw Error(option + " " + e.what());
  }
  std::error_code ec;
  for (const std::filesystem::path& in : inputs) {
    if (std::filesystem::equivalent(out, in, ec)) {
      throw Error(option + " " + out.string() + ": is the input file " + in.string() +
                  "; give another path (it would be overwritten)");
    }
  }
}

void refuse_dash(const std::filesystem::path& out, const std::string& option,
                 const std::string& what) {
  if (out == "-") {
    throw UsageError(option + " -: " + what);
  }
}

void add_figure_format_option(CLI::App& sub, std::string& format) {
  sub.add_option("--figure-format", format, "Figures as png (default), svg or pdf")
      ->type_name("FORMAT")
      ->check(CLI::IsMember({"png", "svg", "pdf"}));
}

namespace {

std::string cell(double v, const char* format) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace

std::string metrics_header() {
  char line[256];
  std::snprintf(line, sizeof line, "%-12s %6s %10s %9s %9s %10s %10s %9s %7s %9s %12s\n", "scheme",
                "seed", "F RMS [N]", "F max [N]", "F RMS*[N]", "line RMS", "line max", "link [%]",
                "missed", "false al.", "peak cond");
  return line;
}

std::string metrics_row(const std::string& scheme, const std::string& seed, const sim::Metrics& m,
                        const sim::Metrics* outside, double peak_condition) {
  char line[512];
  std::snprintf(line, sizeof line, "%-12s %6s %10s %9s %9s %8s m %8s m %9s %7ld %9ld %12s\n",
                scheme.c_str(), seed.c_str(), cell(m.force.rms(), "%.3f").c_str(),
                cell(m.force.count ? m.force.max : NAN, "%.2f").c_str(),
                outside ? cell(outside->force.rms(), "%.3f").c_str() : "-",
                cell(m.line.rms(), "%.4f").c_str(),
                cell(m.line.count ? m.line.max : NAN, "%.4f").c_str(),
                cell(100.0 * m.isolation_accuracy(), "%.2f").c_str(), m.missed, m.false_alarms,
                cell(peak_condition, "%.3g").c_str());
  return line;
}

void print_metrics_header() { std::fputs(metrics_header().c_str(), stdout); }

void print_metrics_row(const std::string& scheme, const std::string& seed, const sim::Metrics& m,
                       const sim::Metrics* outside, double peak_condition) {
  std::fputs(metrics_row(scheme, seed, m, outside, peak_condition).c_str(), stdout);
}

void add_jobs_option(CLI::App& sub, int& jobs, const std::string& what) {
  jobs = default_jobs();
  sub.add_option("--jobs", jobs,
                 "Cores to use (default: all, here " + std::to_string(jobs) + "): up to N " + what +
                     " at once; the results do not depend on N")
      ->type_name("N")
      ->check(CLI::Range(1, 1024));
}

namespace {

/// `text` wrapped at 96 columns: the first line after `first`, the others after `indent` spaces.
std::string wrapped(std::string_view text, const std::string& first, std::size_t indent) {
  constexpr std::size_t kWidth = 96;
  std::string out;
  std::string line = first;
  bool line_has_words = false;
  while (!text.empty()) {
    const std::size_t space = text.find(' ');
    const std::string_view word = text.substr(0, space);
    text = space == std::string_view::npos ? std::string_view{} : text.substr(space + 1);
    if (line_has_words && line.size() + 1 + word.size() > kWidth) {
      out += line + "\n";
      line = std::string(indent, ' ');
      line_has_words = false;
    }
    line += (line_has_words ? " " : "") + std::string(word);
    line_has_words = true;
  }
  return out + line + "\n";
}

}  // namespace

std::string help_footer(std::initializer_list<HelpExample> examples,
                        const std::string& documentation) {
  // Command lines stay whole (to be copied); the rest wraps for a terminal.
  std::string text = "\nExamples:\n";
  for (const HelpExample& example : examples) {
    text += std::string("  ") + example.command + "\n" + wrapped(example.what, "      ", 6);
  }
  text += "\n" + wrapped(documentation, "Documentation: ", 15);
  text.pop_back();  // CLI11 ends the help with its own newline
  return text;
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
