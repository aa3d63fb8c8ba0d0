#include "figures.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"

namespace extwrench::detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Columns of the decimated plot buffer.
enum Col : int {
  kT = 0,
  kContact,
  kF = 2,
  kFt = 5,
  kL = 8,
  kDir = 11,
  kP = 14,
  kPt = 17,
  kCond = 20,
  kCondTrue,
  kTrueContact,
  kErrF,
  kQ  // q1..qn follow
};

constexpr const char* kAxis[] = {"x", "y", "z"};

// gnuplot's 1-based column of a buffer column.
std::string col(int c) { return std::to_string(c + 1); }

// Text for gnuplot's enhanced mode: '_' and '^' would start sub- and superscripts.
std::string enhanced(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '_' || c == '^' || c == '@' || c == '&' || c == '~' || c == '{' || c == '}')
      out += '\\';
    out += c;
  }
  return out;
}

void write_script(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw Error(path.string() + ": cannot create the file");
  out << text;
}

// What every figure's script needs.
struct PlotContext {
  std::filesystem::path dir;
  std::string data;   // plot_data.txt, as a gnuplot string
  std::string title;  // the run's name
  int n = 0;          // joints
  bool truth = false;
};

struct Figure {
  std::filesystem::path script;
  std::filesystem::path png;
};

Figure figure(const PlotContext& c, const std::string& name) {
  return {c.dir / (name + ".gp"), c.dir / (name + ".png")};
}

// Fig. 5: joint positions.
Figure plot_joints(const PlotContext& c) {
  const Figure f = figure(c, "joints");
  std::ostringstream s;
  s << gnuplot_png_preamble(f.png) << "set title "
    << gnuplot_quote("Joint positions — " + enhanced(c.title))
    << "\nset xlabel 't [s]'\nset ylabel 'q_i [rad]'\nplot ";
  for (int i = 0; i < c.n; ++i) {
    s << (i ? ", " : "") << c.data << " using 1:" << col(kQ + i) << " with lines lw 2 title 'q_"
      << i + 1 << "'";
  }
  s << "\n";
  write_script(f.script, s.str());
  return f;
}

// Figs. 6 / 8: estimated and true force, and the error norm (the contact flag without truth).
Figure plot_force(const PlotContext& c) {
  const Figure f = figure(c, "force");
  std::ostringstream s;
  s << gnuplot_png_preamble(f.png, 1000, 1000) << "set multiplot layout 4,1 title "
    << gnuplot_quote("External force, world frame — " + enhanced(c.title)) << "\n"
    << "set key inside right top horizontal\nset lmargin 10\n";
  for (int k = 0; k < 3; ++k) {
    s << "set ylabel 'F_" << kAxis[k] << " [N]'\nunset xlabel\nplot " << c.data
      << " using 1:" << col(kF + k) << " with lines lw 2 lc rgb '#1f77b4' title 'estimated'";
    if (c.truth)
      s << ", " << c.data << " using 1:" << col(kFt + k)
        << " with lines lw 2 dt 2 lc rgb '#d62728' title 'true'";
    s << "\n";
  }
  if (c.truth) {
    s << "set ylabel '|F_{est} - F| [N]'\nset xlabel 't [s]'\nset logscale y\nplot " << c.data
      << " using 1:" << col(kErrF)
      << " with lines lw 2 lc rgb '#2ca02c' title 'force error'\nunset logscale y\n";
  } else {
    s << "set ylabel 'contact'\nset xlabel 't [s]'\nset yrange [-0.1:1.1]\nplot " << c.data
      << " using 1:" << col(kContact) << " with steps lw 2 title 'contact detected'\n";
  }
  s << "unset multiplot\n";
  write_script(f.script, s.str());
  return f;
}

// Figs. 7 / 9: p̂ of eq. (20) and the true contact point.
Figure plot_line_point(const PlotContext& c) {
  const Figure f = figure(c, "line_point");
  std::ostringstream s;
  s << gnuplot_png_preamble(f.png, 1000, 850) << "set multiplot layout 3,1 title "
    << gnuplot_quote("Point of the line of action p̂ (eq. 20), world frame — " + enhanced(c.title))
    << "\n"
    << "set key inside right top horizontal\nset lmargin 10\n";
  for (int k = 0; k < 3; ++k) {
    s << "set ylabel 'p_" << kAxis[k] << " [m]'\n"
      << (k == 2 ? "set xlabel 't [s]'\n" : "unset xlabel\n") << "plot " << c.data
      << " using 1:" << col(kL + k) << " with lines lw 2 lc rgb '#1f77b4' title 'estimated p̂'";
    if (c.truth)
      s << ", " << c.data << " using 1:" << col(kPt + k)
        << " with lines lw 2 dt 2 lc rgb '#d62728' title 'true point'";
    s << "\n";
  }
  s << "unset multiplot\n";
  write_script(f.script, s.str());
  return f;
}

// Fig. 10: condition numbers.
Figure plot_condition(const PlotContext& c) {
  const Figure f = figure(c, "condition");
  std::ostringstream s;
  s << gnuplot_png_preamble(f.png, 1000, 600) << "set title "
    << gnuplot_quote("Condition number — " + enhanced(c.title))
    << "\nset xlabel 't [s]'\nset ylabel 'σ_{max} / σ_{min}'\nset logscale y\nset key inside "
       "left top\nplot "
    << c.data << " using 1:" << col(kCond)
    << " with lines lw 2 lc rgb '#1f77b4' title 'Jacobian inverted by the estimator'";
  if (c.truth) {
    s << ", " << c.data << " using 1:" << col(kCondTrue)
      << " with lines lw 2 dt 2 lc rgb '#d62728' title 'J of O_l (world frame, SI), l = true "
         "contact link'";
  }
  s << "\n";
  write_script(f.script, s.str());
  return f;
}

// The rows of the 3-D view: `count` instants at the middles of equal slices of the kept rows.
std::vector<int> snapshot_rows(int available, int snapshots) {
  std::vector<int> rows;
  const int count = std::max(1, std::min(snapshots, available));
  for (int k = 0; k < count && available > 0; ++k) {
    rows.push_back(
        static_cast<int>((static_cast<long long>(available - 1) * (2 * k + 1)) / (2 * count)));
  }
  return rows;
}

// One point, or "NaN NaN NaN" (gnuplot draws nothing) when absent; then the block's end.
void point_block(std::ostream& out, bool present, const double* p) {
  if (present) {
    out << p[0] << " " << p[1] << " " << p[2] << "\n";
  } else {
    out << "NaN NaN NaN\n";
  }
  out << "\n\n";
}

// One snapshot's four blocks (gnuplot index 4k .. 4k+3): the skeleton (sensor, then body
// origins), the true point, the line of action (± 0.3 m about p̂), the surface point. Returns
// the half-width of a cube that holds the skeleton, at least `extent`.
double write_snapshot(std::ostream& out, const Model& model, Data& data, const double* row,
                      bool truth, const Vector3& p_WS, double extent) {
  const int n = model.nq();
  VectorX q(n);
  for (int i = 0; i < n; ++i) q[i] = row[kQ + i];
  forward_kinematics(model, data, q);
  out << p_WS.x() << " " << p_WS.y() << " " << p_WS.z() << "\n";  // the base sensor
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Vector3& p = data.X_WB[b].translation;
    out << p.x() << " " << p.y() << " " << p.z() << "\n";
    extent = std::max(extent, p.cwiseAbs().maxCoeff());
  }
  out << "\n\n";
  point_block(out, truth && row[kTrueContact] > 0.5, row + kPt);
  if (std::isfinite(row[kL]) && std::isfinite(row[kDir])) {
    for (const double lambda : {-0.3, 0.3}) {
      out << row[kL] + lambda * row[kDir] << " " << row[kL + 1] + lambda * row[kDir + 1] << " "
          << row[kL + 2] + lambda * row[kDir + 2] << "\n";
    }
    out << "\n\n";
  } else {
    point_block(out, false, nullptr);
  }
  point_block(out, std::isfinite(row[kP]), row + kP);
  return extent;
}

// The 3-D view's script: one splot per snapshot, in a grid of two columns.
std::string robot3d_script(const PlotContext& c, const Figure& f, const Decimator& rows,
                           const std::vector<int>& shots, double extent, const Vector3& p_WS) {
  std::ostringstream s;
  const int cols = shots.size() > 1 ? 2 : 1;
  const int lines = static_cast<int>((shots.size() + 1) / 2);
  s << gnuplot_png_preamble(f.png, 1100, 550 * std::max(1, lines)) << "set multiplot layout "
    << std::max(1, lines) << "," << cols << " title "
    << gnuplot_quote("Robot, true contact point and estimated line of action — " +
                     enhanced(c.title))
    << "\n"
    << "set view 62,30,1.2\nset view equal xyz\n"
    << "set xrange [" << -extent << ":" << extent << "]\nset yrange [" << -extent << ":" << extent
    << "]\nset zrange [" << std::min(-0.35, p_WS.z() - 0.05) << ":" << extent + 0.1 << "]\n"
    << "set xlabel 'x [m]'\nset ylabel 'y [m]'\nset zlabel 'z [m]'\nset key at screen 0.99, "
       "screen 0.995 top right samplen 2\n"
    << "set ticslevel 0\n";
  for (std::size_t k = 0; k < shots.size(); ++k) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "t = %.2f s", rows.row(shots[k])[kT]);
    s << "set title '" << buf << "'\n"
      << "splot 'robot3d.txt' index " << 4 * k
      << " with linespoints lw 4 pt 7 ps 1 lc rgb '#555555' title "
      << (k == 0 ? "'links (sensor, joint frame origins)'" : "''") << ", "
      << "'' index " << 4 * k + 1 << " with points pt 7 ps 2 lc rgb '#d62728' title "
      << (k == 0 ? "'true point'" : "''") << ", "
      << "'' index " << 4 * k + 2 << " with lines lw 3 lc rgb '#1f77b4' title "
      << (k == 0 ? "'estimated line of action'" : "''") << ", "
      << "'' index " << 4 * k + 3 << " with points pt 9 ps 2 lc rgb '#2ca02c' title "
      << (k == 0 ? "'estimated surface point'" : "''") << "\n";
  }
  s << "unset multiplot\n";
  return s.str();
}

// The 3-D view at a few instants: robot3d.txt and its script.
Figure plot_robot3d(const PlotContext& c, const Model& model, const Decimator& rows, int snapshots,
                    const Vector3& p_WS) {
  const Figure f = figure(c, "robot3d");
  const std::vector<int> shots = snapshot_rows(rows.rows(), snapshots);
  Data data(model);
  std::ofstream out(c.dir / "robot3d.txt");
  double extent = 0.3;
  for (const int r : shots)
    extent = write_snapshot(out, model, data, rows.row(r), c.truth, p_WS, extent);
  out.close();
  write_script(f.script, robot3d_script(c, f, rows, shots, extent, p_WS));
  return f;
}

// gnuplot draws on one core and the figures are independent: two at a time. A failure is
// reported for the first failing script in order, as a sequential run would report it.
void run_gnuplot_scripts(const std::vector<Figure>& figures) {
  std::vector<std::exception_ptr> errors(figures.size());
  std::atomic<std::size_t> next{0};
  auto run_some = [&] {
    for (std::size_t k = next++; k < figures.size(); k = next++) {
      try {
        run_gnuplot(figures[k].script);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  std::thread helper(run_some);
  run_some();
  helper.join();
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace

FigureRecorder::FigureRecorder(const Model& model, bool truth, int max_points)
    : model_(model),
      truth_(truth),
      rows_(kQ + model.nq(), max_points),
      row_(static_cast<std::size_t>(kQ + model.nq())),
      data_(model) {}

void FigureRecorder::add(const Sample& sample, const ContactEstimate& estimate) {
  if (!rows_.wants_next()) {
    rows_.skip();
    return;
  }
  double* r = row_.data();
  r[kT] = sample.t;
  estimate_columns(estimate, r);
  truth_columns(sample, estimate, r);
  for (int i = 0; i < model_.nq(); ++i) r[kQ + i] = sample.q[i];
  rows_.push(r);
}

void FigureRecorder::estimate_columns(const ContactEstimate& e, double* r) const {
  r[kContact] = e.contact ? 1.0 : 0.0;
  for (int k = 0; k < 3; ++k) {
    r[kF + k] = e.contact ? e.force_W[k] : kNaN;
    r[kL + k] = e.contact ? e.line_point_W[k] : kNaN;
    r[kDir + k] = e.contact ? e.line_direction_W[k] : kNaN;
    r[kP + k] = e.contact ? e.point_W[k] : kNaN;
  }
  r[kCond] = e.condition_number;
}

void FigureRecorder::truth_columns(const Sample& s, const ContactEstimate& e, double* r) {
  const bool touched = truth_ && s.truth.body >= 0;
  for (int k = 0; k < 3; ++k) {
    r[kFt + k] = truth_ ? (touched ? s.truth.force[k] : 0.0) : kNaN;
    r[kPt + k] = touched ? s.truth.point[k] : kNaN;
  }
  r[kTrueContact] = touched ? 1.0 : 0.0;
  r[kCondTrue] = kNaN;
  if (truth_ && s.truth.body > 0) {
    forward_kinematics(model_, data_, s.q);
    r[kCondTrue] = jacobian_condition(model_, data_, s.truth.body);
  }
  r[kErrF] = kNaN;
  if (truth_) {
    const Vector3 f_true = s.truth.body >= 0 ? s.truth.force : Vector3::Zero();
    const Vector3 f_est = e.contact && e.has(EstimateFlag::kForce) ? e.force_W : Vector3::Zero();
    r[kErrF] = (f_est - f_true).norm();
  }
}

std::vector<std::filesystem::path> FigureRecorder::draw(const FigureOptions& o) const {
  const std::filesystem::path data = o.dir / "plot_data.txt";
  rows_.write(data);
  const PlotContext c{o.dir, gnuplot_quote(data.filename().string()), o.title, model_.nq(), truth_};
  // In braces: evaluated in order, so the files are written in the order of the list.
  const std::vector<Figure> figures{plot_joints(c), plot_force(c), plot_line_point(c),
                                    plot_condition(c),
                                    plot_robot3d(c, model_, rows_, o.snapshots, o.p_WS)};
  run_gnuplot_scripts(figures);
  std::vector<std::filesystem::path> pngs;
  for (const Figure& f : figures) pngs.push_back(f.png);
  return pngs;
}

}  // namespace extwrench::detail
