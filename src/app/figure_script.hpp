// What the replay's figure scripts share (figures.cpp: time plots; robot3d.cpp: the 3-D view):
// the columns of the recorded rows and the helpers that write gnuplot text. Private to the app
// library.
#pragma once

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "extwrench/app/gnuplot.hpp"

namespace extwrench::detail {

// Columns of a recorded row (plot_data.txt); the per-joint blocks (JointBlock) follow kQ.
enum Col : int {
  kT = 0,
  kContact,
  kF = 2,          // estimated force, W (NaN where partial: kFPartial)
  kFt = 5,         // true force, W
  kL = 8,          // p̂ of eq. (20)
  kDir = 11,       // unit direction of the line of action
  kP = 14,         // estimated (surface) point
  kPt = 17,        // true point
  kCond = 20,      // cond of the Jacobian the estimator inverted
  kCondTrue,       // cond(J of O_l), l = true contact link
  kCondEstimated,  // cond(J of O_l), l = estimated contact link
  kIll,            // 1 when the estimate is flagged ill_conditioned (damped)
  kTrueContact,
  kErrF,
  kFPartial,                   // the force of estimates flagged partial (observable part only), W
  kBaseForce = kFPartial + 3,  // ‖F̂_ext‖ of the base sensor (detection's force signal)
  kForceThreshold,             // F_min
  kQ
};

// The per-joint blocks after kQ, n columns each: joint_col(kResidual, n, i) is r_i's column.
enum JointBlock : int {
  kPosition = 0,  // q_i
  kDesired,       // q_d,i of the controller, when known
  kResidual,      // r_i = τ̂_ext,i, the signal the detector compares
  kThreshold,     // τ_thr,i in force at that sample (it may follow |q̇_i| and |τ_dyn,i|)
  kTrueTorque,    // true τ_ext,i (logs with true_tau_ext columns)
  kJointBlocks
};
inline constexpr int joint_col(JointBlock block, int n, int i) { return kQ + block * n + i; }
inline constexpr int row_width(int n) { return kQ + kJointBlocks * n; }

inline constexpr const char* kAxis[] = {"x", "y", "z"};

// gnuplot's 1-based column of a row column.
inline std::string col(int c) { return std::to_string(c + 1); }

// Text for gnuplot's enhanced mode: '_' and '^' would start sub- and superscripts.
std::string enhanced(const std::string& text);

// What every figure's script needs.
struct PlotContext {
  std::filesystem::path dir;
  std::string data;   // plot_data.txt, as a gnuplot string
  std::string title;  // the run's name
  int n = 0;          // joints
  bool truth = false;
  FigureFormat format = FigureFormat::kPng;
  std::vector<char> present;             // per column: some value is finite
  std::vector<char> positive;            // per column: some value is > 0 (log scales)
  std::vector<std::string> joint_units;  // per joint: "N m" (revolute) or "N" (prismatic)
  double t_begin = 0.0, t_end = 1.0;     // the time axis, less t_offset [s]
  double t_offset = 0.0;                 // subtracted from the log's t (an epoch's), or 0 [s]
};

// The time axis's label: "t [s]", or "t − 1765140000 [s]" for a log stamped in epoch seconds.
std::string time_label(const PlotContext& c);

struct Figure {
  std::string name;
  std::filesystem::path script;
  std::filesystem::path output;
};

inline Figure figure(const PlotContext& c, const std::string& name) {
  const std::string file = name + "." + std::string(to_string(c.format));
  return {name, c.dir / (name + ".gp"), c.dir / file};
}

// One curve of a time plot: drawn when its column has data (on a log scale: positive data).
struct Series {
  int column;
  std::string style;  // "with lines lw 2 lc rgb '#1f77b4'"
  std::string title;
};

// "plot A, B, ..." of the series that have data; when none has, a labelled empty frame over the
// log's time span ("why" says what is missing), so that no figure fails on an empty series.
void plot_series(std::ostream& s, const PlotContext& c, const std::vector<Series>& series,
                 const std::string& why, bool log_scale = false,
                 const std::string& extra = std::string());

}  // namespace extwrench::detail
