// metrics.json (docs/method.md#metrics): one estimator run's accuracy over stated windows.
// The schema is documented in docs/log_format.md.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "extwrench/sim/metrics.hpp"

namespace extwrench {

struct NamedMetrics {
  std::string name;         ///< e.g. "after_transient", "outside_singularity"
  std::string description;  ///< what the window is, in words
  sim::Metrics metrics;
};

struct MetricsReport {
  std::string scheme;                 ///< scheme name (or the config's file name)
  std::string log;                    ///< the log replayed
  std::string config;                 ///< the estimator configuration
  long rows = 0;                      ///< rows replayed
  double t_begin = 0.0, t_end = 0.0;  ///< time span of the log [s]
  bool surface_metrics = false;       ///< whether the surface-point error is meaningful
  std::vector<std::pair<std::string, std::string>> notes;  ///< extra key → text
  std::vector<NamedMetrics> windows;
};

/// The report as JSON text (NaN as null; numbers with round-trip precision).
[[nodiscard]] std::string metrics_json(const MetricsReport& report);
/// Writes metrics_json to `path`; throws extwrench::Error if it cannot.
void write_metrics_json(const std::filesystem::path& path, const MetricsReport& report);

}  // namespace extwrench
