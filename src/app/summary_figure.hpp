// The cross-seed summary figure of a scenario run (app/scenario_run.hpp). Private to the app
// library.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "extwrench/app/scenario_run.hpp"

namespace extwrench::detail {

/// Writes DIR/summary.txt, summary.gp and draws summary.<format> through `outputs`: per scheme
/// and seed the force error RMS (and outside the singularity), the line-of-action RMS, with
/// the scenario's targets as dotted lines. A failure is a warning on stderr: nullopt.
std::optional<std::filesystem::path> draw_summary(const Scenario& s,
                                                  const std::vector<SeedResult>& results,
                                                  const std::filesystem::path& dir,
                                                  FigureFormat format, OutputFiles& outputs);

}  // namespace extwrench::detail
