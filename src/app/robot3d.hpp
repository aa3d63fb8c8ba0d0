// The replay's 3-D view: the robot at a few instants (contact instants first) with its links'
// collision shapes (primitives as wireframes, meshes as sampled triangle outlines), the estimated
// force as an arrow at its point, the line of action, the estimated and the true point. Private
// to the app library.
#pragma once

#include "extwrench/geometry/shapes.hpp"
#include "extwrench/io/output_files.hpp"
#include "extwrench/model/model.hpp"
#include "figure_script.hpp"

namespace extwrench::detail {

struct Robot3dInput {
  const Model& model;
  const GeometryModel* geometry;  // null: no shapes drawn
  const Decimator& rows;          // whole recorded rows (figure_script.hpp's columns)
  int snapshots;
  Vector3 p_WS;  // the base sensor's origin
  bool truth;
};

/// Writes robot3d.txt and robot3d.gp through `outputs`; the figure is drawn by the caller.
Figure plot_robot3d(const PlotContext& c, const Robot3dInput& in, OutputFiles& outputs);

}  // namespace extwrench::detail
