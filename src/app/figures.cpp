#include "figures.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/io/number_text.hpp"
#include "figure_script.hpp"
#include "robot3d.hpp"

namespace extwrench::detail {

std::string enhanced(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '_' || c == '^' || c == '@' || c == '&' || c == '~' || c == '{' || c == '}')
      out += '\\';
    out += c;
  }
  return out;
}

std::string time_label(const PlotContext& c) {
  if (c.t_offset == 0.0) return "'t [s]'";
  return gnuplot_quote("t − " + format_number(c.t_offset) + " [s]");
}

void plot_series(std::ostream& s, const PlotContext& c, const std::vector<Series>& series,
                 const std::string& why, bool log_scale, const std::string& extra) {
  std::string list;
  for (const Series& x : series) {
    const auto k = static_cast<std::size_t>(x.column);
    if (!(log_scale ? c.positive[k] : c.present[k])) continue;
    list += (list.empty() ? "" : ", ") + c.data + " using 1:" + col(x.column) + " " + x.style +
            " title " + gnuplot_quote(x.title);
  }
  // Every time axis spans the log exactly, so that the panels of a figure line up (gnuplot's
  // autoscale rounds to a tic: a panel with data ended at 12 s beside an empty one at 10.5 s).
  const double t1 = c.t_end > c.t_begin ? c.t_end : c.t_begin + 1.0;
  s << "set xrange [" << c.t_begin << ":" << t1 << "]\n";
  if (list.empty()) {
    // An empty frame: gnuplot refuses to autoscale y on no data.
    s << "unset logscale y\nset yrange [0:1]\n"
      << "set label 1 " << gnuplot_quote(enhanced(why)) << " at graph 0.5, 0.5 center\n"
      << "plot 2 notitle\nunset label 1\nset autoscale y\n";
    return;
  }
  if (log_scale) s << "set logscale y\n";
  s << "plot " << list << extra << "\n";
  if (log_scale) s << "unset logscale y\n";
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Keys sit outside the plot area, on the right, so that they never hide a curve or a title.
constexpr const char* kKey = "set key outside right top vertical samplen 2\n";

// Fig. 5: joint positions, and the desired ones when the controller's trajectory is known.
std::string joints_script(const PlotContext& c, const Figure& f) {
  std::ostringstream s;
  s << gnuplot_preamble(f.output, c.format, 1100, 700) << kKey << "set title "
    << gnuplot_quote("Joint positions — " + enhanced(c.title)) << "\nset xlabel " << time_label(c)
    << "\nset ylabel 'q_i [rad]'\n";
  std::vector<Series> series;
  for (int i = 0; i < c.n; ++i) {
    const std::string lt = " lt " + std::to_string(i + 1);
    series.push_back(
        {joint_col(kPosition, c.n, i), "with lines lw 2" + lt, "q_" + std::to_string(i + 1)});
    series.push_back({joint_col(kDesired, c.n, i), "with lines lw 1 dt 2" + lt,
                      "q_{d," + std::to_string(i + 1) + "}"});
  }
  plot_series(s, c, series, "no joint positions in the log");
  return s.str();
}

// Figs. 6 / 8: estimated and true force, and the error norm (the contact flag without truth).
std::string force_script(const PlotContext& c, const Figure& f) {
  std::ostringstream s;
  s << gnuplot_preamble(f.output, c.format, 1100, 1000) << kKey << "set multiplot layout 4,1 title "
    << gnuplot_quote("External force, world frame — " + enhanced(c.title)) << "\n"
    << "set lmargin 10\nset rmargin 22\n";
  for (int k = 0; k < 3; ++k) {
    s << "set ylabel 'F_" << kAxis[k] << " [N]'\nunset xlabel\n";
    plot_series(s, c,
                {{kF + k, "with linespoints lw 2 pt 7 ps 0.3 lc rgb '#1f77b4'", "estimated"},
                 {kFPartial + k, "with points pt 7 ps 0.5 lc rgb '#999999'", "partial"},
                 {kFt + k, "with lines lw 2 dt 2 lc rgb '#d62728'", "true"}},
                "no force estimated (no contact detected)");
  }
  s << "set xlabel " << time_label(c) << "\n";
  if (c.truth) {
    s << "set ylabel '|F_{est} - F| [N]'\n";
    plot_series(s, c, {{kErrF, "with lines lw 2 lc rgb '#2ca02c'", "force error"}},
                "no force error above zero", true);
  } else {
    s << "set ylabel 'contact'\nset yrange [-0.1:1.1]\n";
    plot_series(s, c, {{kContact, "with steps lw 2", "contact detected"}}, "no rows");
  }
  s << "unset multiplot\n";
  return s.str();
}

// Figs. 7 / 9: p̂ of eq. (20) and the true contact point.
std::string line_point_script(const PlotContext& c, const Figure& f) {
  std::ostringstream s;
  s << gnuplot_preamble(f.output, c.format, 1100, 850) << kKey << "set multiplot layout 3,1 title "
    << gnuplot_quote("Point of the line of action p̂ (eq. 20), world frame — " + enhanced(c.title))
    << "\nset lmargin 10\nset rmargin 22\n";
  for (int k = 0; k < 3; ++k) {
    s << "set ylabel 'p_" << kAxis[k] << " [m]'\n"
      << (k == 2 ? "set xlabel " + time_label(c) + "\n" : "unset xlabel\n");
    plot_series(s, c,
                {{kL + k, "with linespoints lw 2 pt 7 ps 0.3 lc rgb '#1f77b4'", "estimated p̂"},
                 {kPt + k, "with lines lw 2 dt 2 lc rgb '#d62728'", "true point"}},
                "no line of action estimated");
  }
  s << "unset multiplot\n";
  return s.str();
}

// The time spans where a 0/1 column (ill_conditioned, contact) is set, as shaded rectangles
// behind the curves; spans closer than 1/kMaxSpans of the log are merged, so that a flag that
// flickers draws a few rectangles, not thousands.
std::string flagged_spans(const EnvelopeDecimator& rows, int column, const char* colour,
                          double t_begin, double t_end) {
  constexpr int kMaxSpans = 200;
  const double gap = (t_end - t_begin) / kMaxSpans;
  std::vector<std::pair<double, double>> spans;
  for (int i = 0; i < rows.rows(); ++i) {
    const double* r = rows.row(i);
    if (!(r[column] > 0.5)) continue;
    if (!spans.empty() && r[kT] - spans.back().second <= gap) {
      spans.back().second = r[kT];
    } else {
      spans.emplace_back(r[kT], r[kT]);
    }
  }
  std::ostringstream s;
  int id = 10;
  for (const auto& [a, b] : spans) {
    s << "set object " << id++ << " rect from " << a << ", graph 0 to "
      << std::max(b, a + gap * 0.2) << ", graph 1 behind fc rgb '" << colour
      << "' fs solid 1.0 noborder\n";
  }
  return s.str();
}

constexpr const char* kDampedColour = "#fdd0c8";
constexpr const char* kContactColour = "#dbe7f4";

// Fig. 10: condition numbers, the solver's damping threshold and the damped spans.
std::string condition_script(const PlotContext& c, const Figure& f, const EnvelopeDecimator& rows,
                             double max_condition) {
  std::ostringstream s;
  s << gnuplot_preamble(f.output, c.format, 1100, 600) << kKey << "set title "
    << gnuplot_quote("Condition number — " + enhanced(c.title)) << "\nset xlabel " << time_label(c)
    << "\nset ylabel 'σ_{max} / σ_{min}'\n";
  const std::string spans = flagged_spans(rows, kIll, kDampedColour, c.t_begin, c.t_end);
  s << spans;
  std::string extra;
  if (max_condition > 0.0) {
    extra = ", " + std::to_string(max_condition) +
            " with lines lw 1.5 dt 3 lc rgb 'black' title 'damping threshold'";
    // The threshold inside the frame, not on its top edge (the autoscaled top was often the
    // threshold itself): an undrawn line at 3 × the threshold raises the autoscaled top.
    extra += ", " + std::to_string(3.0 * max_condition) + " with lines lt nodraw notitle";
  }
  if (!spans.empty())
    extra += std::string(", keyentry with boxes fc rgb '") + kDampedColour +
             "' fs solid 1.0 noborder title 'damped (flagged)'";
  plot_series(
      s, c,
      {{kCond, "with lines lw 2 lc rgb '#1f77b4'", "J inverted by the estimator"},
       {kCondTrue, "with lines lw 2 dt 2 lc rgb '#d62728'", "J of O_l, l = true link"},
       {kCondEstimated, "with lines lw 2 dt 2 lc rgb '#2ca02c'", "J of O_l, l = estimated link"}},
      "no Jacobian (no contact detected)", true, extra);
  return s.str();
}

// What the detector compared, one panel per joint: r_i = τ̂_ext,i between ±τ_thr,i (thresholds
// that follow the motion drawn as they were at each sample) and the true τ_ext,i when logged;
// with a base sensor a last panel of ‖F̂_ext‖ against F_min; declared contact shaded. It shows
// which joint raised an alarm and by how much, the margin a threshold keeps in free motion.
std::string residual_script(const PlotContext& c, const Figure& f, const EnvelopeDecimator& rows) {
  const bool force_panel = c.present[kForceThreshold] != 0;
  const int panels = c.n + (force_panel ? 1 : 0);
  std::ostringstream s;
  s << gnuplot_preamble(f.output, c.format, 1100, 120 + 150 * panels) << kKey
    << "set multiplot layout " << panels << ",1 title "
    << gnuplot_quote("Detection: residuals r_i and thresholds ±τ_{thr,i} — " + enhanced(c.title))
    << "\nset lmargin 10\nset rmargin 22\n";
  const std::string spans = flagged_spans(rows, kContact, kContactColour, c.t_begin, c.t_end);
  s << spans;
  const std::string contact_key =
      spans.empty() ? std::string()
                    : std::string(", keyentry with boxes fc rgb '") + kContactColour +
                          "' fs solid 1.0 noborder title 'contact declared'";
  for (int i = 0; i < c.n; ++i) {
    const std::string j = std::to_string(i + 1);
    const int threshold = joint_col(kThreshold, c.n, i);
    s << "set ylabel 'r_{" << j << "} [" << c.joint_units[static_cast<std::size_t>(i)] << "]'\n"
      << (i + 1 == panels ? "set xlabel " + time_label(c) + "\n" : "unset xlabel\n");
    std::string extra;
    // −τ_thr, and undrawn curves at ±1.15 τ_thr so that autoscale keeps both lines inside the
    // frame (on a quiet joint they would lie on its edges).
    if (c.present[static_cast<std::size_t>(threshold)]) {
      const std::string t = "$" + col(threshold);
      extra = ", " + c.data + " using 1:(-" + t + ") with lines lw 1 lc rgb 'black' notitle, " +
              c.data + " using 1:(1.15*" + t + ") with lines lt nodraw notitle, " + c.data +
              " using 1:(-1.15*" + t + ") with lines lt nodraw notitle";
    }
    if (i == 0) extra += contact_key;
    plot_series(
        s, c,
        {{joint_col(kResidual, c.n, i), "with lines lw 1.5 lc rgb '#1f77b4'", "r_{" + j + "}"},
         {joint_col(kTrueTorque, c.n, i), "with lines lw 1.5 dt 2 lc rgb '#d62728'",
          "true τ_{ext," + j + "}"},
         {threshold, "with lines lw 1 lc rgb 'black'", "±τ_{thr," + j + "}"}},
        "no residual (the estimator never started)", false, extra);
  }
  if (force_panel) {
    s << "set ylabel '‖F_{ext}‖ [N]'\nset xlabel " << time_label(c) << "\n";
    plot_series(s, c,
                {{kBaseForce, "with lines lw 1.5 lc rgb '#1f77b4'", "‖F_{ext}‖, base sensor"},
                 {kForceThreshold, "with lines lw 1 lc rgb 'black'", "F_{min}"}},
                "no base force (the sensor was taring)");
  }
  s << "unset multiplot\n";
  return s.str();
}

// The per-column facts the scripts need: which columns have data, and the time span.
PlotContext context_of(const FigureOptions& o, const EnvelopeDecimator& rows, const Model& model,
                       bool truth) {
  const int n = model.nq();
  PlotContext c;
  for (int i = 1; i <= n; ++i) {
    const bool prismatic = model.joints[static_cast<std::size_t>(i)].type == JointType::kPrismatic;
    c.joint_units.emplace_back(prismatic ? "N" : "N m");
  }
  c.dir = o.dir;
  c.data = gnuplot_quote("plot_data.txt");
  c.title = o.title;
  c.n = n;
  c.truth = truth;
  c.format = o.format;
  c.present.assign(static_cast<std::size_t>(rows.width()), 0);
  c.positive.assign(static_cast<std::size_t>(rows.width()), 0);
  for (int i = 0; i < rows.rows(); ++i) {
    const double* r = rows.row(i);
    for (int k = 0; k < rows.width(); ++k) {
      if (std::isfinite(r[k])) c.present[static_cast<std::size_t>(k)] = 1;
      if (std::isfinite(r[k]) && r[k] > 0.0) c.positive[static_cast<std::size_t>(k)] = 1;
    }
  }
  if (rows.rows() > 0) {
    c.t_begin = rows.row(0)[kT];
    c.t_end = rows.row(rows.rows() - 1)[kT];
  }
  return c;
}

// gnuplot draws on one core and the figures are independent: two at a time. Each draws to
// its ".partial" name; the error of a failed one is kept for the caller.
std::vector<std::string> run_scripts(const std::vector<Figure>& figures) {
  std::vector<std::string> errors(figures.size());
  std::atomic<std::size_t> next{0};
  auto run_some = [&] {
    for (std::size_t k = next++; k < figures.size(); k = next++) {
      try {
        run_gnuplot(figures[k].script, OutputFiles::partial_name(figures[k].output));
      } catch (const std::exception& e) {
        errors[k] = e.what();
        if (errors[k].empty()) errors[k] = "gnuplot failed";
      }
    }
  };
  std::thread helper(run_some);
  run_some();
  helper.join();
  return errors;
}

}  // namespace

FigureRecorder::FigureRecorder(const Model& model, bool truth, bool base_sensor, int max_points,
                               const sim::SinusoidalTrajectory* desired)
    : model_(model),
      truth_(truth),
      base_sensor_(base_sensor),
      desired_(desired != nullptr && desired->size() == model.nq() ? desired : nullptr),
      rows_(row_width(model.nq()), max_points),
      snapshot_rows_(row_width(model.nq()), 64),
      row_(static_cast<std::size_t>(row_width(model.nq()))),
      data_(model),
      q_d_(model.nq()),
      dq_d_(model.nq()),
      ddq_d_(model.nq()) {}

namespace {
double true_link_condition(const Model& model, Data& data, bool truth, const Sample& s) {
  if (!truth || s.truth.body <= 0) return kNaN;
  forward_poses(model, data, s.q);  // all jacobian_condition needs
  return jacobian_condition(model, data, s.truth.body);
}
}  // namespace

std::function<double(const Sample&)> FigureRecorder::true_condition() const {
  auto data = std::make_shared<Data>(model_);
  return [&model = model_, truth = truth_, data](const Sample& s) {
    return true_link_condition(model, *data, truth, s);
  };
}

void FigureRecorder::add(const Sample& sample, const ContactEstimate& estimate,
                         const ContactDetector& detector, double true_condition) {
  double* r = row_.data();
  const int n = model_.nq();
  // gnuplot cannot draw an axis 6 s long at 1.8e9 s (its range is "empty" below a relative
  // 1e-8): a log stamped in epoch seconds is drawn from its first whole second.
  if (!started_) {
    t_offset_ = std::abs(sample.t) >= kEpochTime ? std::floor(sample.t) : 0.0;
    started_ = true;
  }
  r[kT] = sample.t - t_offset_;
  estimate_columns(sample, estimate, r);
  truth_columns(sample, estimate, true_condition, r);
  detection_columns(sample, estimate, detector, r);
  if (desired_ != nullptr) desired_->evaluate(sample.t, q_d_, dq_d_, ddq_d_);
  for (int i = 0; i < n; ++i) {
    r[joint_col(kPosition, n, i)] = sample.q[i];
    r[joint_col(kDesired, n, i)] = desired_ != nullptr ? q_d_[i] : kNaN;
  }
  rows_.push(r);
  snapshot_rows_.push(r);
}

void FigureRecorder::estimate_columns(const Sample& s, const ContactEstimate& e, double* r) {
  r[kContact] = e.contact ? 1.0 : 0.0;
  // A partial estimate is the observable part of the force only (docs/estimator.md#partial-
  // observability): drawn apart, so that it is not read as the force.
  const bool partial = e.contact && e.has(EstimateFlag::kPartial);
  for (int k = 0; k < 3; ++k) {
    r[kF + k] = e.contact && !partial ? e.force_W[k] : kNaN;
    r[kFPartial + k] = partial ? e.force_W[k] : kNaN;
    r[kL + k] = e.contact ? e.line_point_W[k] : kNaN;
    r[kDir + k] = e.contact ? e.line_direction_W[k] : kNaN;
    r[kP + k] = e.contact ? e.point_W[k] : kNaN;
  }
  r[kCond] = e.condition_number;
  r[kIll] = e.has(EstimateFlag::kIllConditioned) ? 1.0 : 0.0;
  r[kCondEstimated] = kNaN;
  // On a log without truth, the contact link's conditioning is still worth seeing.
  if (!truth_ && e.contact && e.link > 0 && s.q.size() == model_.nq()) {
    forward_poses(model_, data_, s.q);  // all jacobian_condition needs
    r[kCondEstimated] = jacobian_condition(model_, data_, e.link);
  }
}

// What the detector compared at this sample: r_i against τ_thr,i (which may follow the motion)
// and, with a base sensor, ‖F̂_ext‖ against F_min; the true τ_ext,i beside them when logged.
void FigureRecorder::detection_columns(const Sample& s, const ContactEstimate& e,
                                       const ContactDetector& d, double* r) const {
  const int n = model_.nq();
  const VectorX& threshold = d.thresholds();
  for (int i = 0; i < n; ++i) {
    r[joint_col(kResidual, n, i)] = e.residual.size() == n ? e.residual[i] : kNaN;
    r[joint_col(kThreshold, n, i)] = threshold.size() == n ? threshold[i] : kNaN;
    r[joint_col(kTrueTorque, n, i)] =
        s.has_true_tau_ext && s.truth.tau_ext.size() == n ? s.truth.tau_ext[i] : kNaN;
  }
  // With a sensor the estimate's force is F̂_ext of eq. (11) (Table I, cases A-D), what the
  // detector compares with F_min; none while the sensor is taring.
  const bool base_force = base_sensor_ && e.has(EstimateFlag::kForce) &&
                          !e.has(EstimateFlag::kTaring) && e.force_W.allFinite();
  r[kBaseForce] = base_force ? e.force_W.norm() : kNaN;
  r[kForceThreshold] = base_sensor_ ? d.options().f_min : kNaN;
}

void FigureRecorder::truth_columns(const Sample& s, const ContactEstimate& e, double true_condition,
                                   double* r) {
  const bool touched = truth_ && s.truth.body >= 0;
  for (int k = 0; k < 3; ++k) {
    r[kFt + k] = truth_ ? (touched ? s.truth.force_W[k] : 0.0) : kNaN;
    r[kPt + k] = touched ? s.truth.point_W[k] : kNaN;
  }
  r[kTrueContact] = touched ? 1.0 : 0.0;
  // Every row (not only kept ones): the envelope keeps the singular peak (Fig. 10).
  r[kCondTrue] =
      std::isnan(true_condition) ? true_link_condition(model_, data_, truth_, s) : true_condition;
  r[kErrF] = kNaN;
  if (truth_) {
    const Vector3 f_true = s.truth.body >= 0 ? s.truth.force_W : Vector3::Zero();
    const Vector3 f_est = e.contact && e.has(EstimateFlag::kForce) ? e.force_W : Vector3::Zero();
    r[kErrF] = (f_est - f_true).norm();
  }
}

DrawnFigures FigureRecorder::draw(const FigureOptions& o, OutputFiles& parent) const {
  // A transaction of their own: a failure half-way (disk full) removes every figure file and
  // leaves the command's other outputs alone; on success the parent owns the files.
  OutputFiles outputs;
  const std::filesystem::path data = o.dir / "plot_data.txt";
  rows_.write(outputs.stage(data));
  outputs.commit(data);
  PlotContext c = context_of(o, rows_, model_, truth_);
  c.t_offset = t_offset_;
  std::vector<Figure> figures{figure(c, "joints"), figure(c, "force"), figure(c, "line_point"),
                              figure(c, "condition"), figure(c, "residual")};
  outputs.write_text(figures[0].script, joints_script(c, figures[0]));
  outputs.write_text(figures[1].script, force_script(c, figures[1]));
  outputs.write_text(figures[2].script, line_point_script(c, figures[2]));
  outputs.write_text(figures[3].script, condition_script(c, figures[3], rows_, o.max_condition));
  outputs.write_text(figures[4].script, residual_script(c, figures[4], rows_));
  const Robot3dInput in{model_, o.geometry, snapshot_rows_, o.snapshots, o.p_WS, truth_};
  figures.push_back(plot_robot3d(c, in, outputs));
  for (const Figure& f : figures) (void)outputs.stage(f.output);  // gnuplot draws to .partial
  DrawnFigures drawn;
  const std::vector<std::string> errors = run_scripts(figures);
  for (std::size_t k = 0; k < figures.size(); ++k) {
    if (errors[k].empty()) {
      outputs.commit(figures[k].output);
      drawn.files.push_back(figures[k].output);
    } else {
      outputs.discard(figures[k].output);
      drawn.failures.push_back(figures[k].name + ": " + errors[k]);
    }
  }
  for (const auto& file : outputs.committed()) parent.adopt(file);
  outputs.keep();
  return drawn;
}

}  // namespace extwrench::detail
