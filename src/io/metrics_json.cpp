#include "extwrench/io/metrics_json.hpp"

#include <cerrno>
#include <cmath>
#include <fstream>

#include "extwrench/core/error.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/output_files.hpp"
#include "extwrench/io/text_quoting.hpp"

namespace extwrench {
namespace {

std::string str(const std::string& s) { return double_quoted(s); }

std::string num(double x) {
  if (!std::isfinite(x)) return "null";
  return format_number(x);
}

std::string stat(const sim::ErrorStat& s, const char* unit) {
  return "{\"rms\": " + num(s.rms()) + ", \"max\": " + num(s.count > 0 ? s.max : std::nan("")) +
         ", \"samples\": " + std::to_string(s.count) + ", \"unit\": \"" + unit + "\"}";
}

std::string window(const sim::MetricsWindow& w) {
  std::string out = "{\"from\": " + num(w.from) + ", \"to\": " + num(w.to) + ", \"exclude\": [";
  for (std::size_t i = 0; i < w.exclude.size(); ++i) {
    if (i) out += ", ";
    out += "[" + num(w.exclude[i].first) + ", " + num(w.exclude[i].second) + "]";
  }
  return out + "]}";
}

}  // namespace

std::string metrics_json(const MetricsReport& r) {
  std::string o = "{\n";
  o += "  \"scheme\": " + str(r.scheme) + ",\n";
  o += "  \"log\": " + str(r.log) + ",\n";
  o += "  \"config\": " + str(r.config) + ",\n";
  o += "  \"rows\": " + std::to_string(r.rows) + ",\n";
  o += "  \"t_begin\": " + num(r.t_begin) + ",\n";
  o += "  \"t_end\": " + num(r.t_end) + ",\n";
  for (const auto& [k, v] : r.notes) o += "  " + str(k) + ": " + str(v) + ",\n";
  o += "  \"windows\": [";
  for (std::size_t i = 0; i < r.windows.size(); ++i) {
    const NamedMetrics& nm = r.windows[i];
    const sim::Metrics& m = nm.metrics;
    o += i ? ",\n    {\n" : "\n    {\n";
    o += "      \"name\": " + str(nm.name) + ",\n";
    o += "      \"description\": " + str(nm.description) + ",\n";
    o += "      \"window\": " + window(m.window) + ",\n";
    o += "      \"samples\": " + std::to_string(m.samples) + ",\n";
    o += "      \"contact_samples\": " + std::to_string(m.contact_samples) + ",\n";
    o += "      \"free_samples\": " + std::to_string(m.free_samples) + ",\n";
    o += "      \"force_error\": " + stat(m.force, "N") + ",\n";
    o += "      \"moment_error\": " + stat(m.moment, "N m") + ",\n";
    o += "      \"line_of_action_distance\": " + stat(m.line, "m") + ",\n";
    if (r.surface_metrics) {
      o += "      \"surface_point_error\": " + stat(m.surface, "m") + ",\n";
    } else {
      o += "      \"surface_point_error\": null,\n";
    }
    o += "      \"force_not_estimated\": " + std::to_string(m.force_not_estimated) + ",\n";
    o += "      \"line_not_estimated\": " + std::to_string(m.line_not_estimated) + ",\n";
    o += "      \"isolation_accuracy\": " + num(m.isolation_accuracy()) + ",\n";
    o += "      \"right_link_samples\": " + std::to_string(m.right_link) + ",\n";
    o += "      \"missed_detections\": " + std::to_string(m.missed) + ",\n";
    o += "      \"false_alarms\": " + std::to_string(m.false_alarms) + ",\n";
    o += "      \"false_alarms_release\": " + std::to_string(m.false_alarms_release) + ",\n";
    o += "      \"false_alarm_rate\": " + num(m.false_alarm_rate()) + ",\n";
    o += "      \"uncertainty\": {\"samples\": " + std::to_string(m.sigma_samples) +
         ", \"force_within_2sigma\": " + num(m.force_two_sigma_coverage()) +
         ", \"uncertain\": " + std::to_string(m.uncertain) +
         ", \"large_force_error_unflagged\": " + std::to_string(m.large_force_error_unflagged) +
         "}\n";
    o += "    }";
  }
  o += "\n  ],\n";
  // Detection delay is counted over the whole log (onsets anywhere), the same in every window.
  const sim::Metrics* any = r.windows.empty() ? nullptr : &r.windows.front().metrics;
  o += "  \"detection_delay\": {\"window\": \"whole log\", \"onsets\": " +
       std::to_string(any ? any->onsets : 0) +
       ", \"detected\": " + std::to_string(any ? any->onsets_detected : 0) +
       ", \"already_declared\": " + std::to_string(any ? any->onsets_already_declared : 0) +
       ", \"mean\": " + num(any ? any->mean_detection_delay() : std::nan("")) +
       ", \"max\": " + num(any && any->onsets_detected > 0 ? any->delay_max : std::nan("")) +
       ", \"unit\": \"s\"}\n";
  o += "}\n";
  return o;
}

void write_metrics_json(const std::filesystem::path& path, const MetricsReport& report) {
  errno = 0;
  std::ofstream out(path);
  if (!out) throw Error(OutputFiles::cannot_create(path, errno));
  out << metrics_json(report);
  if (!out) throw Error(path.string() + ": write failed");
}

}  // namespace extwrench
