// extwrench dynamics: inverse dynamics and the predicted base sensor reading for each row of a
// CSV of states (docs/method.md#newton-euler-and-the-base-sensor).
#include <algorithm>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/dynamics/rnea.hpp"
#include "extwrench/io/csv.hpp"
#include "extwrench/io/output_files.hpp"

namespace extwrench::cli {
namespace {

struct DynamicsOptions {
  std::filesystem::path robot;
  std::string sensor_pose;
  bool sensor_pose_given = false;  // an empty --sensor-pose "" is an error, not the default
  std::string in;
  std::string out;
  std::vector<std::filesystem::path> package_path;
  std::vector<std::string> lock;
  std::string root_body, tip_body;  ///< MJCF only
  std::string gravity;              ///< "gx gy gz" in the root frame, or "" for the model's
};

/// --gravity "gx gy gz" [m/s^2]: three finite numbers (spaces or commas between them).
Vector3 parse_gravity(const std::string& text) {
  const auto fail = [&](const std::string& why) {
    return UsageError("--gravity: " + why + " in '" + text +
                      "'; expected three numbers \"gx gy gz\" [m/s^2] in the root frame, e.g. "
                      "--gravity \"0 9.81 0\" for a robot mounted on a wall");
  };
  const std::vector<double> g = parse_numbers(text, 3, "three", fail);
  if (g.size() != 3) throw fail(std::to_string(g.size()) + " number" + (g.size() == 1 ? "" : "s"));
  return {g[0], g[1], g[2]};
}

/// Columns of the input for an n-joint robot: t, q1..qn, dq1..dqn, ddq1..ddqn.
std::vector<std::string> state_columns(int n) {
  std::vector<std::string> names{"t"};
  for (const char* prefix : {"q", "dq", "ddq"}) {
    for (int i = 1; i <= n; ++i) names.push_back(prefix + std::to_string(i));
  }
  return names;
}

std::vector<std::string> output_columns(int n) {
  std::vector<std::string> names{"t"};
  for (int i = 1; i <= n; ++i) names.push_back("tau" + std::to_string(i));
  for (const char* s : {"fs_x", "fs_y", "fs_z", "ms_x", "ms_y", "ms_z"}) names.emplace_back(s);
  return names;
}

void run_dynamics(const DynamicsOptions& opt) {
  // Check the command line before any file is touched: a usage error is reported first.
  std::optional<Pose> given_pose;
  if (opt.sensor_pose_given) given_pose = parse_pose(opt.sensor_pose, "--sensor-pose");
  const std::optional<Vector3> gravity =
      opt.gravity.empty() ? std::nullopt : std::optional<Vector3>(parse_gravity(opt.gravity));
  const std::filesystem::path out_path(opt.out);
  if (opt.out != "-") check_output_file(out_path, "--out", {opt.robot, opt.in});

  // Inverse dynamics needs no geometry: a mesh that cannot be found (package://) is no error here.
  LoadOptions load = robot_load_options(opt.package_path, opt.lock, opt.root_body, opt.tip_body);
  load.load_meshes = false;
  if (gravity) load.gravity = *gravity;
  const RobotDescription robot = load_robot_file(opt.robot, load);
  const Model& model = robot.model;
  const int n = model.nq();
  std::string which = "--sensor-pose";
  const Pose X_WS = given_pose ? *given_pose : default_sensor_pose(model, &which);
  // On stderr: stdout may be the CSV (--out -).
  std::cerr << "extwrench dynamics: base sensor pose X_WS: " << pose_summary(X_WS) << " (" << which
            << ")\n";

  std::unique_ptr<CsvReader> reader =
      opt.in == "-" ? std::make_unique<CsvReader>(std::cin, "<stdin>")
                    : std::make_unique<CsvReader>(std::filesystem::path(opt.in));

  // Resolve every column once; report all that are missing together.
  const std::vector<std::string> wanted = state_columns(n);
  std::vector<int> index;
  std::string missing;
  for (const std::string& name : wanted) {
    const auto c = reader->find_column(name);
    if (!c) missing += (missing.empty() ? "" : ", ") + name;
    index.push_back(c.value_or(-1));
  }
  if (!missing.empty()) {
    throw Error(reader->name() + ":1: missing column(s) " + missing + " (the robot has " +
                std::to_string(n) + " joints, so the header needs t, q1..q" + std::to_string(n) +
                ", dq1..dq" + std::to_string(n) + ", ddq1..ddq" + std::to_string(n) + ")");
  }
  std::string extra;
  std::size_t extras = 0;
  constexpr std::size_t kShown = 10;  // a header of 10 000 stray columns must not print them all
  for (const std::string& name : reader->header()) {
    if (std::find(wanted.begin(), wanted.end(), name) != wanted.end()) continue;
    if (++extras <= kShown) extra += (extra.empty() ? "" : ", ") + name;
  }
  if (extras > kShown) extra += " and " + std::to_string(extras - kShown) + " more";
  if (!extra.empty()) std::cerr << "extwrench dynamics: ignoring column(s) " << extra << "\n";

  // OUT.csv.partial until complete: a failed run leaves nothing that looks like a result.
  OutputFiles outputs;
  if (opt.out != "-" && out_path.has_parent_path())
    outputs.create_directories(out_path.parent_path());
  std::unique_ptr<CsvWriter> writer =
      opt.out == "-" ? std::make_unique<CsvWriter>(std::cout, output_columns(n), "<stdout>")
                     : std::make_unique<CsvWriter>(outputs.stage(out_path), output_columns(n));

  Data data(model);
  VectorX q(n), dq(n), ddq(n);
  const auto at = [&](int k) { return index[static_cast<std::size_t>(k)]; };
  while (reader->next_row()) {
    const double t = reader->number(at(0));
    for (int i = 0; i < n; ++i) {
      q[i] = reader->number(at(1 + i));
      dq[i] = reader->number(at(1 + n + i));
      ddq[i] = reader->number(at(1 + 2 * n + i));
    }
    const VectorX& tau = rnea(model, data, q, dq, ddq);
    const Vector6 reading = sensor_reading(data, X_WS);  // [f_m; n_m] in S, about O_s (eqs. 9–10)
    writer->add(t);
    for (int i = 0; i < n; ++i) writer->add(tau[i]);
    for (int k = 0; k < 6; ++k) writer->add(reading[k]);
    writer->end_row();
  }
  writer->close();
  if (opt.out != "-") {
    outputs.commit(out_path);
    outputs.keep();
    std::cerr << "extwrench dynamics: " << reader->rows_read() << " row(s) written to " << opt.out
              << "\n";
  }
}

}  // namespace

void register_dynamics(CLI::App& app) {
  auto opt = std::make_shared<DynamicsOptions>();
  CLI::App* sub = app.add_subcommand("dynamics",
                                     "Joint torques (inverse dynamics) and the predicted base "
                                     "force/torque sensor reading for each "
                                     "row of a CSV of states");
  sub->add_option("--robot", opt->robot, kRobotFileHelp)->required()->type_name("FILE");
  sub->add_option("--in", opt->in,
                  "CSV with a header row and columns t, q1..qn, dq1..dqn, ddq1..ddqn [s, rad or m, "
                  "/s, /s^2], any order; other columns are ignored; '-' reads stdin")
      ->required()
      ->type_name("STATES.csv");
  sub->add_option(
         "--out", opt->out,
         "CSV written with t, tau1..taun [N m or N], fs_x fs_y fs_z [N], ms_x ms_y ms_z [N m]; "
         "'-' writes to stdout")
      ->required()
      ->type_name("OUT.csv");
  CLI::Option* pose_option =
      sub->add_option(
             "--sensor-pose", opt->sensor_pose,
             "Pose of the base sensor in the root frame, \"x y z roll pitch yaw\" (m, rad, URDF "
             "rpy). Default: the model's frame 'sensor', else the root link's origin, aligned")
          ->type_name("\"X Y Z R P Y\"");
  sub->add_option("--gravity", opt->gravity,
                  "Gravity in the root frame [m/s^2], \"gx gy gz\" (a robot on a wall or a "
                  "ceiling). Default: the model's, 0 0 -9.81 for a URDF")
      ->type_name("\"GX GY GZ\"");
  add_package_path_option(*sub, opt->package_path);
  add_lock_option(*sub, opt->lock);
  add_chain_options(*sub, opt->root_body, opt->tip_body);
  sub->footer(
      "\nThe reading is what the robot discharges onto the sensor: force and moment about the "
      "sensor\n"
      "origin, in the sensor frame (link 0's weight included). Numbers are written in the "
      "shortest\n"
      "form that reads back to the same double.\n" +
      help_footer({{"extwrench dynamics --robot models/paper_arm.yaml --in states.csv --out "
                    "predicted.csv",
                    "joint torques and the base sensor's reading for each row t, q1..qn, "
                    "dq1..dqn, ddq1..ddqn"},
                   {"extwrench dynamics --robot models/paper_arm.urdf --sensor-pose \"0 0 -0.05 "
                    "0 0 3.1416\" --in states.csv --out -",
                    "the same with the sensor 5 cm below the root link, turned by 180 deg; CSV "
                    "to stdout"}},
                  "docs/cli.md (dynamics, CSV), docs/conventions.md (frames and signs)"));
  sub->callback([opt, pose_option] {
    opt->sensor_pose_given = pose_option->count() > 0;
    run_dynamics(*opt);
  });
}

}  // namespace extwrench::cli
