// The replay's figures (gnuplot; docs/simulation.md lists them): rows are recorded while the
// log streams by, decimated so that memory does not grow with the log (min/max envelope: peaks
// survive), and the data and scripts are written and drawn at the end. Each figure is drawn
// to a temporary name and renamed when gnuplot succeeded; a figure that fails is reported, not
// fatal. Private to the app library.
#pragma once

#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "extwrench/app/gnuplot.hpp"
#include "extwrench/core/sample.hpp"
#include "extwrench/dynamics/data.hpp"
#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/estimation/detection.hpp"
#include "extwrench/geometry/shapes.hpp"
#include "extwrench/io/output_files.hpp"
#include "extwrench/sim/trajectory.hpp"

namespace extwrench::detail {

/// Where and how the figures are drawn.
struct FigureOptions {
  std::filesystem::path dir;       ///< plot_data.txt, robot3d.txt, the scripts and figures
  std::string title;               ///< the run's name, in every title
  int snapshots = 4;               ///< instants of the 3-D view
  Vector3 p_WS = Vector3::Zero();  ///< the base sensor's origin, drawn below link 0
  double max_condition = 0.0;      ///< the solver's damping threshold (0: not drawn)
  FigureFormat format = FigureFormat::kPng;
  const GeometryModel* geometry = nullptr;  ///< collision shapes of the 3-D view (may be null)
};

/// The figures drawn, and one message per figure that could not be drawn.
struct DrawnFigures {
  std::vector<std::filesystem::path> files;
  std::vector<std::string> failures;
};

class FigureRecorder {
 public:
  /// truth: the log has truth columns (true force and point, the force error, cond(J) of the
  /// true contact link). base_sensor: the estimator reads a base sensor (its ‖F̂_ext‖ is a
  /// detection signal). desired: the trajectory the controller tracked (q_d in the joint
  /// plot), or null. About 2·max_points rows are kept.
  FigureRecorder(const Model& model, bool truth, bool base_sensor, int max_points,
                 const sim::SinusoidalTrajectory* desired = nullptr);

  /// One replayed sample, the estimate at it and the detector that made it (its thresholds).
  /// true_condition: cond(J) of the sample's true contact link as true_condition() computes it,
  /// when the caller computed it elsewhere (a replay: on the reader's thread); NaN: computed here.
  void add(const Sample& sample, const ContactEstimate& estimate, const ContactDetector& detector,
           double true_condition = std::numeric_limits<double>::quiet_NaN());

  /// cond(J) of a sample's true contact link (NaN without truth or contact), with a workspace
  /// of its own: for another thread. The envelope keeps the singular peak (Fig. 10), so every
  /// row needs it, a fifth of a replay's estimating thread otherwise.
  [[nodiscard]] std::function<double(const Sample&)> true_condition() const;

  /// Writes the data and the scripts and runs gnuplot on them, every file through `outputs`;
  /// the figures in the order joints, force, line_point, condition, residual, robot3d.
  [[nodiscard]] DrawnFigures draw(const FigureOptions& options, OutputFiles& outputs) const;

 private:
  void estimate_columns(const Sample& s, const ContactEstimate& e, double* row);
  void detection_columns(const Sample& s, const ContactEstimate& e, const ContactDetector& d,
                         double* row) const;
  void truth_columns(const Sample& s, const ContactEstimate& e, double true_condition, double* row);

  const Model& model_;
  bool truth_;
  bool base_sensor_;
  const sim::SinusoidalTrajectory* desired_;
  EnvelopeDecimator rows_;   // the time plots
  Decimator snapshot_rows_;  // whole rows (real configurations) for the 3-D view
  std::vector<double> row_;  // the row being filled
  bool started_ = false;     // a first sample was added (it sets t_offset_)
  double t_offset_ = 0.0;    // subtracted from t on the time axes (an epoch's seconds), or 0
  static constexpr double kEpochTime = 1e6;  // [s]: 11.6 days, a clock's epoch and not a run's
  Data data_;                                // kinematics for cond(J) of the contact links
  VectorX q_d_, dq_d_, ddq_d_;
};

}  // namespace extwrench::detail
