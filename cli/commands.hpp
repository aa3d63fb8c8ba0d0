// The extwrench command-line tool: one file per subcommand, each exposing a register function
// that adds the subcommand, its options and its callback to the app (main.cpp lists them).
// Subcommands parse, call the library and print; the library does the work.
//
// Exit codes: 0 success, 1 an input problem (a file that cannot be read or is malformed: the
// callback throws extwrench::Error), 2 a usage problem (the command line itself: CLI11 parse
// errors, or UsageError thrown by a callback).
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "extwrench/core/types.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/sim/metrics.hpp"

namespace extwrench::cli {

/// A command line that cannot work, found after parsing (e.g. --sensor-pose "1 2"): exit 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void register_info(CLI::App& app);
void register_dynamics(CLI::App& app);
void register_estimate(CLI::App& app);
void register_simulate(CLI::App& app);
void register_calibrate(CLI::App& app);

// ---- helpers shared by subcommands (common.cpp) --------------------------------------------

/// What a robot file option accepts (load_robot's formats), for every command's --help.
inline constexpr const char* kRobotFileHelp =
    "Robot file: URDF (.urdf, .xml), DH table (.yaml, .yml) or MJCF (.xml, .mjcf with root "
    "<mujoco>, when built with MuJoCo)";

/// The numbers of an option's value, separated by spaces, tabs or commas, at most `most` of them
/// (`most_words`: "six"). Throws fail("'x' is not a finite number") or fail("more than six
/// numbers"); the caller checks how many it needs.
[[nodiscard]] std::vector<double> parse_numbers(
    const std::string& text, std::size_t most, const char* most_words,
    const std::function<UsageError(const std::string&)>& fail);

/// "x y z roll pitch yaw" (metres, radians; URDF's fixed-axis rpy; spaces or commas between
/// the six numbers) as a Pose. Throws UsageError naming `option` otherwise.
[[nodiscard]] Pose parse_pose(const std::string& text, const std::string& option);

/// Adds `--package-path DIR` (repeatable) for package:// URIs to a subcommand.
void add_package_path_option(CLI::App& sub, std::vector<std::filesystem::path>& dirs);

/// Adds `--lock NAME=VALUE` (repeatable): joints held fixed at VALUE [rad | m] (a tree's extra
/// branches, a gripper's fingers), LoadOptions::locked_joints.
void add_lock_option(CLI::App& sub, std::vector<std::string>& locks);

/// Adds `--root-body BODY` and `--tip-body BODY`: the chain of an MJCF scene
/// (LoadOptions::root_body, tip_body; root_body, tip_body in a configuration or scenario).
void add_chain_options(CLI::App& sub, std::string& root_body, std::string& tip_body);

/// LoadOptions from --package-path, --lock, --root-body and --tip-body; throws UsageError for a
/// --lock that is not NAME=VALUE with a finite number, or a joint locked twice.
[[nodiscard]] LoadOptions robot_load_options(const std::vector<std::filesystem::path>& package_path,
                                             const std::vector<std::string>& locks,
                                             const std::string& root_body,
                                             const std::string& tip_body);

/// Loads a URDF or DH YAML with those options (package directories, ROS_PACKAGE_PATH, locks).
[[nodiscard]] RobotDescription load_robot_file(const std::filesystem::path& path,
                                               const LoadOptions& options);

/// The base sensor pose X_WS used when none is given: the frame named "sensor" if the model
/// has one (it must be on link 0), else the root link's origin, aligned with it.
/// `description` says which, for messages.
[[nodiscard]] Pose default_sensor_pose(const Model& model, std::string* description);

/// "xyz (x, y, z) m, rpy (r, p, y) rad" of a pose, for the start-up messages.
[[nodiscard]] std::string pose_summary(const Pose& X);

/// Checks an output file named on the command line before any work: `option` (e.g. "--out")
/// must name a file that OutputFiles can write (not a directory, symbolic link, device or FIFO)
/// and none of `inputs` (the same file would be overwritten while, or after, it is read).
void check_output_file(const std::filesystem::path& out, const std::string& option,
                       std::initializer_list<std::filesystem::path> inputs);

/// "-" for --out of a command that writes a file or a directory, not standard output: a usage
/// error "OPTION -: WHAT" (a file or directory named "-" is never what was meant).
void refuse_dash(const std::filesystem::path& out, const std::string& option,
                 const std::string& what);

/// Adds `--figure-format png|svg|pdf` to a subcommand.
void add_figure_format_option(CLI::App& sub, std::string& format);

/// The metrics table of `simulate` and `estimate` (same columns, same precision): the header,
/// then one row per run. `outside` (the window outside the singularity) and peak_condition
/// (NaN) may be absent: "-".
void print_metrics_header();
void print_metrics_row(const std::string& scheme, const std::string& seed, const sim::Metrics& m,
                       const sim::Metrics* outside, double peak_condition);

/// The same lines as text (a job's output, buffered to print in order).
[[nodiscard]] std::string metrics_header();
[[nodiscard]] std::string metrics_row(const std::string& scheme, const std::string& seed,
                                      const sim::Metrics& m, const sim::Metrics* outside,
                                      double peak_condition);

/// Adds `--jobs N` (N ≥ 1, else a usage error; default app/jobs.hpp's default_jobs(), the
/// number of cores) to a subcommand; `what` names the jobs ("logs replayed").
void add_jobs_option(CLI::App& sub, int& jobs, const std::string& what);

/// One example of a command's --help: the command line and what it does.
struct HelpExample {
  const char* command;
  const char* what;
};

/// The end of a command's --help: its examples (each command line, then what it does, indented
/// below it), then where its documentation is. Every command's help ends with such a footer, so
/// a newcomer sees a working command line beside the options.
[[nodiscard]] std::string help_footer(std::initializer_list<HelpExample> examples,
                                      const std::string& documentation);

/// Number for humans: up to 10 significant digits ("17.9", "-0.0875", "1e-06").
[[nodiscard]] std::string fmt(double value);
/// "(x, y, z)" with fmt.
[[nodiscard]] std::string fmt(const Vector3& v);

}  // namespace extwrench::cli
