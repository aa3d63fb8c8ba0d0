// The replay's figures (PNG through gnuplot; docs/simulation.md lists them): rows are recorded
// while the log streams by, decimated so that memory does not grow with the log, and the data
// and scripts are written and drawn at the end. Private to the app library.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "extwrench/app/gnuplot.hpp"
#include "extwrench/core/sample.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/estimation/contact_estimate.hpp"

namespace extwrench::detail {

/// Where and how the figures are drawn.
struct FigureOptions {
  std::filesystem::path dir;       ///< plot_data.txt, robot3d.txt, the scripts and PNGs
  std::string title;               ///< the run's name, in every title
  int snapshots = 4;               ///< instants of the 3-D view
  Vector3 p_WS = Vector3::Zero();  ///< the base sensor's origin, drawn below link 0
};

class FigureRecorder {
 public:
  /// truth: the log has truth columns (true force and point, the force error, cond(J) of the
  /// true contact link). At most about 2·max_points rows are kept.
  FigureRecorder(const Model& model, bool truth, int max_points);

  /// One replayed sample and the estimate at it. Only kept rows are computed.
  void add(const Sample& sample, const ContactEstimate& estimate);

  /// Writes the data and the five scripts, runs gnuplot on them; the PNGs in the order joints,
  /// force, line_point, condition, robot3d.
  [[nodiscard]] std::vector<std::filesystem::path> draw(const FigureOptions& options) const;

 private:
  void estimate_columns(const ContactEstimate& e, double* row) const;
  void truth_columns(const Sample& s, const ContactEstimate& e, double* row);

  const Model& model_;
  bool truth_;
  Decimator rows_;
  std::vector<double> row_;  // the row being filled
  Data data_;                // kinematics for cond(J) of the true contact link
};

}  // namespace extwrench::detail
