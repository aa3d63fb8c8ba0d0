#include "extwrench/app/joint_range.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "extwrench/io/number_text.hpp"

namespace extwrench {

JointRangeCheck::JointRangeCheck(const Model& model, Margin margin) : model_(&model) {
  const int n = model.nq();
  for (int i = 1; i <= n; ++i) {
    const Joint& j = model.joints[static_cast<std::size_t>(i)];
    const double range = j.upper - j.lower;
    // No limits (continuous), or none worth the name (lower = upper = 0: a URDF's default, an
    // exporter's placeholder): nothing to check against.
    const bool checked = std::isfinite(range) && range > 0.0;
    const double widen = margin == Margin::kLog ? std::max(0.1 * range, 0.1) : 0.0;
    lower_.push_back(checked ? j.lower - widen : -std::numeric_limits<double>::infinity());
    upper_.push_back(checked ? j.upper + widen : std::numeric_limits<double>::infinity());
  }
  excursions_.resize(lower_.size());
}

void JointRangeCheck::add(double t, const Eigen::Ref<const VectorX>& q_row) noexcept {
  ++rows_;
  if (static_cast<std::size_t>(q_row.size()) != lower_.size()) return;
  for (std::size_t i = 0; i < lower_.size(); ++i) {
    const double q = q_row[static_cast<Eigen::Index>(i)];
    const double beyond = q < lower_[i] ? lower_[i] - q : q > upper_[i] ? q - upper_[i] : 0.0;
    if (!(beyond > 0.0)) continue;
    Excursion& e = excursions_[i];
    ++e.rows;
    if (beyond > e.beyond) e = {e.rows, beyond, q, t};
  }
}

bool JointRangeCheck::mostly_outside() const noexcept {
  return std::any_of(excursions_.begin(), excursions_.end(),
                     [&](const Excursion& e) { return 2 * e.rows > rows_; });
}

std::string JointRangeCheck::note() const {
  const auto most =
      std::max_element(excursions_.begin(), excursions_.end(),
                       [](const Excursion& a, const Excursion& b) { return a.rows < b.rows; });
  if (most == excursions_.end() || most->rows == 0) return {};
  const auto worst = static_cast<std::size_t>(most - excursions_.begin());
  const auto joints = std::count_if(excursions_.begin(), excursions_.end(),
                                    [](const Excursion& e) { return e.rows > 0; });
  const Joint& j = model_->joints[worst + 1];
  char shown[32];
  std::snprintf(shown, sizeof shown, "%.4g", most->q);
  return "q" + std::to_string(worst + 1) + " (joint '" + j.name + "') lies outside its limits [" +
         format_number(j.lower) + ", " + format_number(j.upper) +
         "] (by more than a tenth of the range) on " + std::to_string(most->rows) + " of " +
         std::to_string(rows_) + " rows (up to " + std::string(shown) + ")" +
         (joints > 1 ? ", and " + std::to_string(joints - 1) + " more joint" +
                           (joints > 2 ? "s" : "") + " too"
                     : std::string()) +
         (mostly_outside()
              ? ": are the positions in degrees, or of another robot? The model takes radians "
                "(and metres), in its joints' order"
              : ": an encoder's wrap or a glitch in those rows, or limits in the model that "
                "the robot exceeds? The estimates there use the positions as they are");
}

}  // namespace extwrench
