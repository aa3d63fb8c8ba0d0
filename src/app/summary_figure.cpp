#include "summary_figure.hpp"

#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include "extwrench/core/error.hpp"
#include "extwrench/io/csv.hpp"
#include "figure_script.hpp"

namespace extwrench {
namespace {

const NamedMetrics* window_named(const ReplayResult& r, const std::string& name) {
  for (const auto& w : r.report.windows) {
    if (w.name == name) return &w;
  }
  return nullptr;
}

}  // namespace

double target_metric(const ReplayResult& replay, const std::string& metric) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const NamedMetrics* a = window_named(replay, "after_transient");
  const NamedMetrics* b = window_named(replay, "outside_singularity");
  if (metric == "force_rms_outside") return b ? b->metrics.force.rms() : kNaN;
  if (a == nullptr) return kNaN;
  const sim::Metrics& m = a->metrics;
  if (metric == "force_rms") return m.force.rms();
  if (metric == "line_rms") return m.line.count > 0 ? m.line.rms() : kNaN;
  if (metric == "right_link") return 100.0 * m.isolation_accuracy();
  return kNaN;
}

namespace detail {
namespace {

// One block per scheme: "seed force_rms force_rms_outside line_rms", NaN when absent.
std::string summary_data(const Scenario& s, const std::vector<SeedResult>& results) {
  std::ostringstream d;
  d.precision(10);
  for (const SchemeSpec& scheme : s.schemes) {
    d << "# " << scheme.name << "\n";
    for (const SeedResult& r : results) {
      for (const SchemeResult& sr : r.schemes) {
        if (sr.name != scheme.name) continue;
        d << r.seed;
        for (const char* m : {"force_rms", "force_rms_outside", "line_rms"}) {
          const double v = target_metric(sr.replay, m);
          d << " " << (std::isfinite(v) ? std::to_string(v) : std::string("NaN"));
        }
        d << "\n";
      }
    }
    d << "\n\n";
  }
  return d.str();
}

// The targets of one metric as dotted horizontal lines, labelled with their scheme.
std::string target_lines(const Scenario& s, const std::string& metric, const std::string& also) {
  std::ostringstream t;
  for (const MetricTarget& x : s.targets) {
    if (x.metric != metric && x.metric != also) continue;
    t << "set arrow from graph 0, first " << x.value << " to graph 1, first " << x.value
      << " nohead dt 3 lw 1.5 lc rgb 'black'\nset label "
      << gnuplot_quote(enhanced("target " + x.scheme + " " + x.metric)) << " at graph 0.01, first "
      << x.value << " offset 0, 0.6 font ',9'\n";
  }
  return t.str();
}

// The title, and when there is a second window a smaller second line saying why the two differ:
// the full window holds the singularity crossings, where a scheme without a base sensor cannot
// resolve the force (the paper's Figs. 8-9). Double-quoted: gnuplot reads "\n" there only.
std::string summary_title(const Scenario& s) {
  const auto quoted = [](const std::string& text) {
    std::string out;
    for (const char c : text) {
      if (c == '\\' || c == '"') out += '\\';
      out += c;
    }
    return out;
  };
  std::string title = "\"" + quoted(enhanced("Across seeds — " + s.source.filename().string()));
  if (s.singularity_half_width > 0.0) {
    title += "\\n{/*0.8 " +
             quoted(enhanced("dashed, open points: without ±" +
                             CsvWriter::format(s.singularity_half_width) +
                             " s around each crossing of cond(J of O")) +
             "_{" + quoted(enhanced(s.singularity_link)) + "}" +
             quoted(enhanced(") > " + CsvWriter::format(s.singularity_threshold))) + "}";
  }
  return title + "\"";
}

std::string summary_script(const Scenario& s, const Figure& f, FigureFormat format) {
  std::ostringstream g;
  g << gnuplot_preamble(f.output, format, 1000, 800)
    << "set key outside right top vertical samplen 2\nset multiplot layout 2,1 title "
    << summary_title(s)
    << "\nset lmargin 10\nset rmargin 26\nset xlabel 'seed'\nset xtics 1\nset offsets 0.3, 0.3, "
       "0, 0\nset autoscale xfix\nset yrange [0:*]\n";
  const auto plot = [&](const std::vector<std::pair<int, std::string>>& columns) {
    std::string list;
    for (std::size_t i = 0; i < s.schemes.size(); ++i) {
      for (const auto& [column, suffix] : columns) {
        list += (list.empty() ? "" : ", ") + std::string("'summary.txt' index ") +
                std::to_string(i) + " using 1:" + std::to_string(column) + " with linespoints lt " +
                std::to_string(i + 1) +
                // The second window: thin, dashed, open points, so a scheme whose two
                // windows agree (a base sensor does not mind the singularity) shows a ring
                // around each point instead of hiding one curve under the other.
                (suffix.empty() ? " lw 2 pt 7" : " lw 1 dt 2 pt 6 ps 1.6") + " title " +
                gnuplot_quote(enhanced(s.schemes[i].name + suffix));
      }
    }
    g << "plot " << list << "\nunset arrow\nunset label\n";
  };
  g << "set ylabel 'force error RMS [N]'\n" << target_lines(s, "force_rms", "force_rms_outside");
  // The second window only where the scenario configures it (its column is NaN otherwise).
  if (s.singularity_half_width > 0.0)
    plot({{2, ""}, {3, " (outside singularity)"}});
  else
    plot({{2, ""}});
  g << "set ylabel 'line of action RMS [m]'\n" << target_lines(s, "line_rms", "");
  plot({{4, ""}});
  g << "unset multiplot\n";
  return g.str();
}

}  // namespace

std::optional<std::filesystem::path> draw_summary(const Scenario& s,
                                                  const std::vector<SeedResult>& results,
                                                  const std::filesystem::path& dir,
                                                  FigureFormat format, OutputFiles& parent) {
  PlotContext c;
  c.dir = dir;
  c.format = format;
  const Figure f = figure(c, "summary");
  OutputFiles outputs;  // its own transaction: a failure leaves the run's other files alone
  try {
    outputs.write_text(dir / "summary.txt", summary_data(s, results));
    outputs.write_text(f.script, summary_script(s, f, format));
    (void)outputs.stage(f.output);
    run_gnuplot(f.script, OutputFiles::partial_name(f.output));
    outputs.commit(f.output);
  } catch (const std::exception& e) {
    std::cerr << "extwrench: warning: the summary figure was not drawn: " << e.what() << "\n";
    return std::nullopt;
  }
  for (const auto& file : outputs.committed()) parent.adopt(file);
  outputs.keep();
  return f.output;
}

}  // namespace detail
}  // namespace extwrench
