// Geometry-consistent isolation (docs/estimator.md#geometry-consistent-isolation). The paper's
// rule (Remark 1: the largest joint over τ_min) gives the lowest link l_r that can hold the
// contact: a push on link l whose line passes near the axes of joints l_r+1..l leaves them under
// τ_min, so the true link is any l ≥ l_r. Each candidate l = l_r … n is tested:
//  - the single-contact model on l, with the Table I case of the sensor (the sensor's line for
//    case C, the fit on J_l for D and E), must predict the whole residual τ̂_ext (every joint,
//    zero beyond l) within tolerance × τ_min;
//  - its line of action must meet l's collision shapes.
// Misfit m_l = Σ_i ((τ_pred,i − τ̂_i)/(tolerance τ_min,i))². The consistent candidates whose misfit
// lies within misfit_margin of the smallest explain τ̂ equally well; among them the contact is
// where a pusher coming along the best fit's line first meets the arm: the smallest entry
// abscissa u·p over their shapes. Another entry within ambiguity_distance of the first makes the
// choice kAmbiguous; so does a choice above a candidate that could not be tested (its case not
// observable).
// Real time: noexcept, no allocation (the workspace is sized once).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "extwrench/dynamics/data.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/estimation/damped_least_squares.hpp"
#include "extwrench/estimation/wrench_cases.hpp"
#include "extwrench/geometry/ray.hpp"
#include "extwrench/geometry/shapes.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

enum class IsolationRule : std::uint8_t {
  kResidual,  ///< the paper's rule: the largest joint over τ_min (Remark 1)
  kGeometry,  ///< the candidates l_r … n tested against the residual and the shapes (above)
};

[[nodiscard]] std::string_view to_string(IsolationRule r) noexcept;

struct IsolationOptions {
  /// Unset: kGeometry when some body has a collision shape, else kResidual.
  std::optional<IsolationRule> rule;
  double tolerance = 1.0;            ///< a joint is predicted within tolerance × τ_min,i, > 0
  double ambiguity_distance = 0.01;  ///< [m] ≥ 0: entries this close to the first: ambiguous
  /// ≥ 0: candidates whose misfit exceeds the best fit's by less are equally good by the
  /// residual, and geometry decides among them (0.05: one joint off by 0.22 × tolerance × τ_min).
  double misfit_margin = 0.05;
};

/// The rule in force for a geometry (the default resolved).
[[nodiscard]] IsolationRule resolved_rule(const IsolationOptions& options,
                                          const GeometryModel& geometry) noexcept;

/// What isolate_on_geometry found for one candidate link in its last call: the estimator's
/// later stages take it over for the chosen link instead of computing it again.
struct TestedCandidate {
  WrenchFit fit;  ///< its Table I fit (ok: the case is observable on the link)
  /// Consistent candidates: the line of action p̂ + λ u, and (for the best fit, when its line
  /// meets the link's shapes) its entry, the smallest-λ hit.
  Vector3 line_point_W = Vector3::Zero();
  Vector3 line_direction_W = Vector3::Zero();
  LineHit entry;
  bool has_entry = false;  ///< `entry` is this line's (the best fit's line met its shapes)
  /// The chosen link is not the best fit: `fit` is the best fit's (moment about this link's
  /// origin), the line its line, `entry` where that line first meets this link.
  bool borrowed = false;

  /// True when `entry` was computed for this very line (bit for bit).
  [[nodiscard]] bool is_line(const Vector3& point_W, const Vector3& direction_W) const noexcept {
    return has_entry && point_W == line_point_W && direction_W == line_direction_W;
  }
};

/// Scratch of isolate_on_geometry, sized once for a model (the only allocations).
struct IsolationWorkspace {
  explicit IsolationWorkspace(const Model& model);
  Matrix6X J;                           ///< J_l of a candidate, 6×n
  int jacobian_link = -1;               ///< the candidate J is of (the last one tested), or −1
  VectorX b, tau_pred, tolerance;       ///< (n)
  std::vector<SpectrumGuess> guess;     ///< per candidate link: warm start of the damped solves
  std::vector<TestedCandidate> tested;  ///< per link: valid for the chosen link of the last call

  /// Forgets the warm starts (a reset estimator then matches a fresh one bit for bit).
  void forget_spectra() noexcept;
};

struct IsolationResult {
  int link = -1;                 ///< the chosen link
  std::uint64_t candidates = 0;  ///< bit l: link l consistent (the chosen one included)
  bool ambiguous = false;        ///< another equally good entry within ambiguity_distance, or
                                 ///< a candidate below the chosen link that could not be tested
  bool decided = false;          ///< false: no candidate could be tested (paper's rule kept);
                                 ///< true: ws.tested[link] holds the chosen link's fit and entry
};

/// Inputs of the geometric test, all of the current sample.
struct IsolationInputs {
  SensorType sensor = SensorType::kNone;
  int residual_link = -1;            ///< l_r of the paper's rule (0: base only)
  const VectorX* tau_ext = nullptr;  ///< τ̂_ext (n)
  const VectorX* tau_min = nullptr;  ///< τ_min (n)
  const BaseWrench* base = nullptr;  ///< F̂ and n_m − ñ_g (unused for kNone)
  Vector3 p_WS = Vector3::Zero();    ///< sensor origin
};

/// Tests the candidates l_r … n (data: the poses of the sample). A candidate with no collision
/// shape, or whose case is not observable, cannot be tested and is skipped. When no consistent
/// candidate's line meets its shapes, the result is l_r, decided false.
[[nodiscard]] IsolationResult isolate_on_geometry(
    const Model& model, const Data& data, const GeometryModel& geometry, const IsolationInputs& in,
    const IsolationOptions& options, const SolverOptions& solver, IsolationWorkspace& ws) noexcept;

}  // namespace extwrench
